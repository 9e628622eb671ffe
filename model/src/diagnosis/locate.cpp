#include "model/diagnosis/locate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

namespace model::diagnosis {

LineMeasure measure_line(const OrderSpectrum& rec, const OrderSpectrum& sim, double order,
                         double tolerance, const LocateConfig& cfg) {
  LineMeasure m;
  m.order = order;
  if (rec.amplitude.empty() || !(order > 0.0)) return m;
  double best_order = order;
  double best = rec.tone(order);
  if (tolerance > 0.0) {
    const double r = static_cast<double>(rec.revolutions);
    const auto k0 = static_cast<long long>(std::floor(order * (1.0 - tolerance) * r));
    const auto k1 = static_cast<long long>(std::ceil(order * (1.0 + tolerance) * r));
    for (long long k = std::max(1LL, k0); k <= k1; ++k) {
      const double o = static_cast<double>(k) / r;
      const double a = rec.tone(o);
      if (a > best) {
        best = a;
        best_order = o;
      }
    }
  }
  m.order = best_order;
  m.measured = best;
  m.noise = rec.noise(best_order);
  m.simulated = sim.amplitude.empty() ? 0.0 : sim.tone(best_order);
  const double explained = m.simulated * m.simulated + m.noise * m.noise;
  m.excess = std::max(0.0, m.measured * m.measured - explained);
  m.significant = m.measured >= cfg.snr_min * m.noise && m.measured * m.measured >= cfg.excess_ratio * explained;
  if (!m.significant) m.excess = 0.0;
  return m;
}

namespace {

struct Peak {
  double order = 0.0;
  LineMeasure line;
  bool claimed = false;
};

// Significant excess peaks of a channel's spectrum up to max_order.
std::vector<Peak> excess_peaks(const OrderSpectrum& rec, const OrderSpectrum& sim, double max_order,
                               const LocateConfig& cfg) {
  std::vector<Peak> peaks;
  const auto& a = rec.amplitude;
  if (a.size() < 8) return peaks;
  const double r = static_cast<double>(rec.revolutions);
  const std::size_t k_end = std::min(a.size() - 3, static_cast<std::size_t>(max_order * r));
  for (std::size_t k = std::max<std::size_t>(cfg.min_order_lines, 2); k <= k_end; ++k) {
    if (!(a[k] >= a[k - 1] && a[k] > a[k + 1] && a[k] >= a[k - 2] && a[k] > a[k + 2])) continue;
    const double o = static_cast<double>(k) / r;
    const LineMeasure m = measure_line(rec, sim, o, 0.0, cfg);
    if (m.significant) peaks.push_back({o, m, false});
  }
  return peaks;
}

bool matches(double peak_order, double line_order, double tolerance, double revs) {
  return std::abs(peak_order - line_order) <= std::max(2.5 / revs, tolerance * line_order);
}

void claim_families(const Catalogue& cat, std::size_t channel, Domain domain, FeatureDomain fdomain,
                    std::vector<Peak>& peaks, double revs, double ref_hz, double total,
                    const LocateConfig& cfg, std::vector<ResidualFeature>& out) {
  if (peaks.empty() || !(total > 0.0)) return;
  for (;;) {
    std::size_t best_family = kNoFamily;
    double best_excess = 0.0;
    for (std::size_t f = 0; f < cat.families.size(); ++f) {
      const Family& fam = cat.families[f];
      if (fam.domain != domain || fam.orders.empty()) continue;
      double e = 0.0;
      for (const Peak& p : peaks) {
        if (p.claimed) continue;
        for (double o : fam.orders) {
          if (matches(p.order, o, fam.tolerance, revs)) {
            e += p.line.excess;
            break;
          }
        }
      }
      // Ties go to the family with fewer lines (the narrower explanation).
      if (e > best_excess * (1.0 + 1e-9) ||
          (best_family != kNoFamily && e >= best_excess * (1.0 - 1e-9) && e > 0.0 &&
           fam.orders.size() < cat.families[best_family].orders.size())) {
        best_excess = e;
        best_family = f;
      }
    }
    if (best_family == kNoFamily || best_excess < 0.02 * total) break;
    ResidualFeature feat;
    feat.channel = channel;
    feat.domain = fdomain;
    feat.family = best_family;
    std::vector<const Peak*> mine;
    for (Peak& p : peaks) {
      if (p.claimed) continue;
      for (double o : cat.families[best_family].orders) {
        if (matches(p.order, o, cat.families[best_family].tolerance, revs)) {
          p.claimed = true;
          mine.push_back(&p);
          break;
        }
      }
    }
    std::sort(mine.begin(), mine.end(), [](const Peak* a, const Peak* b) { return a->line.excess > b->line.excess; });
    feat.band_lo_hz = 1e300;
    for (const Peak* p : mine) {
      feat.excess += p->line.excess;
      feat.band_lo_hz = std::min(feat.band_lo_hz, p->order * ref_hz);
      feat.band_hi_hz = std::max(feat.band_hi_hz, p->order * ref_hz);
      feat.max_snr = std::max(feat.max_snr, p->line.measured / std::max(p->line.noise, 1e-300));
      if (feat.peaks_hz.size() < cfg.max_peaks_per_feature) feat.peaks_hz.push_back(p->order * ref_hz);
    }
    feat.share = feat.excess / total;
    out.push_back(std::move(feat));
  }
  // What no family claims, as one feature per domain and channel.
  ResidualFeature rest;
  rest.channel = channel;
  rest.domain = fdomain;
  rest.band_lo_hz = 1e300;
  std::vector<const Peak*> left;
  for (const Peak& p : peaks)
    if (!p.claimed) left.push_back(&p);
  std::sort(left.begin(), left.end(), [](const Peak* a, const Peak* b) { return a->line.excess > b->line.excess; });
  for (const Peak* p : left) {
    rest.excess += p->line.excess;
    rest.band_lo_hz = std::min(rest.band_lo_hz, p->order * ref_hz);
    rest.band_hi_hz = std::max(rest.band_hi_hz, p->order * ref_hz);
    rest.max_snr = std::max(rest.max_snr, p->line.measured / std::max(p->line.noise, 1e-300));
    if (rest.peaks_hz.size() < cfg.max_peaks_per_feature) rest.peaks_hz.push_back(p->order * ref_hz);
  }
  if (rest.excess >= 0.02 * total) {
    rest.share = rest.excess / total;
    out.push_back(std::move(rest));
  }
}

// Band amplification: runs of lines the simulation has that the recording shows stronger
// than the channel's median gain by more than gain_db.
void band_features(std::size_t channel, const OrderSpectrum& rec, const OrderSpectrum& sim, double max_order,
                   double ref_hz, double total, const LocateConfig& cfg, std::vector<ResidualFeature>& out) {
  const auto& s = sim.amplitude;
  if (s.size() < 8 || rec.amplitude.size() < 8) return;
  struct G {
    double order, gain_db, excess, snr;
  };
  std::vector<G> lines;
  const double rs = static_cast<double>(sim.revolutions);
  const std::size_t k_end = std::min(s.size() - 3, static_cast<std::size_t>(max_order * rs));
  for (std::size_t k = 3; k <= k_end; ++k) {
    if (!(s[k] >= s[k - 1] && s[k] > s[k + 1])) continue;
    const double o = static_cast<double>(k) / rs;
    const double sv = sim.tone(o);
    const double m = rec.tone(o);
    const double n = rec.noise(o);
    if (sv < cfg.snr_min * n || m < cfg.snr_min * n) continue;
    lines.push_back({o, 20.0 * std::log10(m / sv), std::max(0.0, m * m - sv * sv - n * n), m / n});
  }
  if (lines.size() < 5) return;
  std::vector<double> gains;
  for (const G& g : lines) gains.push_back(g.gain_db);
  std::nth_element(gains.begin(), gains.begin() + static_cast<long>(gains.size() / 2), gains.end());
  const double median = gains[gains.size() / 2];
  std::size_t i = 0;
  while (i < lines.size()) {
    if (lines[i].gain_db - median <= cfg.gain_db) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < lines.size() && lines[j].gain_db - median > cfg.gain_db) ++j;
    if (j - i >= 3) {
      ResidualFeature f;
      f.channel = channel;
      f.domain = FeatureDomain::kBand;
      f.band_lo_hz = lines[i].order * ref_hz;
      f.band_hi_hz = lines[j - 1].order * ref_hz;
      std::vector<const G*> mine;
      double gsum = 0.0;
      for (std::size_t q = i; q < j; ++q) {
        mine.push_back(&lines[q]);
        f.excess += lines[q].excess;
        gsum += lines[q].gain_db - median;
        f.max_snr = std::max(f.max_snr, lines[q].snr);
      }
      std::sort(mine.begin(), mine.end(), [](const G* a, const G* b) { return a->excess > b->excess; });
      for (const G* g : mine)
        if (f.peaks_hz.size() < cfg.max_peaks_per_feature) f.peaks_hz.push_back(g->order * ref_hz);
      f.gain_db = gsum / static_cast<double>(j - i);
      f.share = total > 0.0 ? std::min(1.0, f.excess / total) : 0.0;
      out.push_back(std::move(f));
    }
    i = j;
  }
}

}  // namespace

LocateResult locate(const Catalogue& cat, const std::vector<ChannelPair>& channels, const LocateConfig& cfg) {
  LocateResult result;
  result.spectrum_total.assign(channels.size(), 0.0);
  result.envelope_total.assign(channels.size(), 0.0);
  // Impulsiveness of each shaft's synchronous average, per channel: kurtosis excess.
  std::vector<std::vector<std::pair<std::string, double>>> impulsive(channels.size());
  for (std::size_t c = 0; c < channels.size(); ++c) {
    const ChannelAnalysis& rec = *channels[c].recorded;
    const ChannelAnalysis& sim = *channels[c].simulated;
    const double ref_hz = rec.spectrum.shaft_hz;
    std::vector<Peak> sp = excess_peaks(rec.spectrum, sim.spectrum, rec.max_order, cfg);
    for (const Peak& p : sp) result.spectrum_total[c] += p.line.excess;
    claim_families(cat, c, Domain::kSpectrum, FeatureDomain::kSpectrum, sp,
                   static_cast<double>(rec.spectrum.revolutions), ref_hz, result.spectrum_total[c], cfg,
                   result.features);
    band_features(c, rec.spectrum, sim.spectrum, rec.max_order, ref_hz, result.spectrum_total[c], cfg,
                  result.features);
    if (!rec.envelope.amplitude.empty()) {
      const double env_top = static_cast<double>(rec.envelope.amplitude.size() - 1) /
                             static_cast<double>(rec.envelope.revolutions) * 0.9;
      std::vector<Peak> ep = excess_peaks(rec.envelope, sim.envelope, env_top, cfg);
      for (const Peak& p : ep) result.envelope_total[c] += p.line.excess;
      claim_families(cat, c, Domain::kEnvelope, FeatureDomain::kEnvelope, ep,
                     static_cast<double>(rec.envelope.revolutions), ref_hz, result.envelope_total[c], cfg,
                     result.features);
    }
    for (const ShaftAverage& ra : rec.averages) {
      for (const ShaftAverage& sa : sim.averages) {
        if (sa.shaft != ra.shaft) continue;
        const double kr = ra.tsa.difference_stats.kurtosis;
        const double ks = sa.tsa.difference_stats.kurtosis;
        if (kr > cfg.impulsive_kurtosis && kr > ks + 1.0) {
          ResidualFeature f;
          f.channel = c;
          f.domain = FeatureDomain::kAverage;
          f.shaft = ra.shaft;
          f.gain_db = kr;
          f.max_snr = kr / std::max(ks, 1.0);
          f.band_lo_hz = 0.0;
          f.band_hi_hz = 0.5 * static_cast<double>(ra.tsa.samples_per_rev) * ra.order * ref_hz;
          result.features.push_back(f);
          impulsive[c].push_back({ra.shaft, kr});
        }
      }
    }
  }

  // Ranking.
  for (std::size_t hi = 0; hi < cat.hypotheses.size(); ++hi) {
    const Hypothesis& h = cat.hypotheses[hi];
    HypothesisScore s;
    s.hypothesis = hi;
    if (h.effect == Effect::kHousingResonance) {
      double total = 0.0, band = 0.0;
      for (std::size_t c = 0; c < channels.size(); ++c) {
        total += result.spectrum_total[c];
        if (channels[c].location != h.location) continue;
        for (const ResidualFeature& f : result.features)
          if (f.channel == c && f.domain == FeatureDomain::kBand) {
            band += f.excess;
            s.best_channel = c;
          }
      }
      s.share = total > 0.0 ? std::min(1.0, band / total) : 0.0;
      s.presence = band > 0.0 ? 1.0 : 0.0;
      s.evidence = band > 0.0 ? cfg.min_evidence : 0.0;
    } else {
      const bool env = h.domain == Domain::kEnvelope;
      double explained = 0.0, total = 0.0, weight = 0.0;
      for (const SignatureLine& l : h.lines) weight += l.weight;
      for (std::size_t c = 0; c < channels.size(); ++c) {
        const ChannelAnalysis& rec = *channels[c].recorded;
        const ChannelAnalysis& sim = *channels[c].simulated;
        const OrderSpectrum& rs = env ? rec.envelope : rec.spectrum;
        const OrderSpectrum& ss = env ? sim.envelope : sim.spectrum;
        total += env ? result.envelope_total[c] : result.spectrum_total[c];
        if (rs.amplitude.empty()) continue;
        const double top = static_cast<double>(rs.amplitude.size() - 3) / static_cast<double>(rs.revolutions);
        double present = 0.0;
        for (const SignatureLine& l : h.lines) {
          if (l.order * (1.0 + h.tolerance) > top || l.order * static_cast<double>(rs.revolutions) < cfg.min_order_lines)
            continue;
          const LineMeasure m = measure_line(rs, ss, l.order, h.tolerance, cfg);
          if (m.significant) {
            explained += l.weight * m.excess;
            present += l.weight;
            s.evidence += l.weight * (m.measured * m.measured) / std::max(m.noise * m.noise, 1e-300);
          }
        }
        if (weight > 0.0 && present / weight > s.presence) {
          s.presence = present / weight;
          s.best_channel = c;
        }
      }
      s.share = total > 0.0 ? std::min(1.0, explained / total) : 0.0;
    }
    s.score = s.evidence >= cfg.min_evidence ? s.share * std::sqrt(s.presence) : 0.0;
    if (h.effect == Effect::kToothCrack && !h.shaft.empty()) {
      double boost = 0.0;
      for (const auto& per : impulsive)
        for (const auto& [shaft, k] : per)
          if (shaft == h.shaft) boost = std::max(boost, std::min(1.0, (k - 3.0) / 3.0));
      s.score *= 1.0 + boost;
    }
    if (s.score > 0.0) result.ranking.push_back(s);
  }
  std::sort(result.ranking.begin(), result.ranking.end(),
            [](const HypothesisScore& a, const HypothesisScore& b) { return a.score > b.score; });
  return result;
}

std::string describe_feature(const Catalogue& cat, const ResidualFeature& f, double ref_hz,
                             const std::vector<ChannelPair>& channels) {
  char buf[256];
  switch (f.domain) {
    case FeatureDomain::kBand:
      std::snprintf(buf, sizeof buf, "lines amplified by %.1f dB over %.0f–%.0f Hz at the sensor on %s: a resonance",
                    f.gain_db, f.band_lo_hz, f.band_hi_hz,
                    f.channel < channels.size() ? channels[f.channel].location.c_str() : "?");
      return buf;
    case FeatureDomain::kAverage:
      std::snprintf(buf, sizeof buf,
                    "impulsive once per %s revolution in its synchronous average (difference-signal kurtosis %.1f)",
                    f.shaft.c_str(), f.gain_db);
      return buf;
    case FeatureDomain::kSpectrum:
    case FeatureDomain::kEnvelope:
      break;
  }
  std::string text;
  if (f.family == kNoFamily || f.family >= cat.families.size()) {
    text = "lines no kinematic family of the drivetrain explains";
  } else {
    const Family& fam = cat.families[f.family];
    text = fam.text;
    if (fam.spacing_order > 0.0) {
      std::snprintf(buf, sizeof buf, " (%.2f Hz)", fam.spacing_order * ref_hz);
      text += buf;
    }
  }
  if (f.domain == FeatureDomain::kEnvelope && f.channel < channels.size()) {
    const ChannelAnalysis* rec = channels[f.channel].recorded;
    std::snprintf(buf, sizeof buf, ", in the envelope of %.0f–%.0f Hz", rec->band.f_lo_hz, rec->band.f_hi_hz);
    text += buf;
  }
  return text;
}

}  // namespace model::diagnosis
