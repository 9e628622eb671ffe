#include "model/diagnosis/locate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

namespace model::diagnosis {

namespace {
bool excluded(double order, double revs, const std::vector<double>* exclude) {
  if (exclude == nullptr) return false;
  for (double o : *exclude)
    if (std::abs(order - o) * revs <= 2.0) return true;
  return false;
}

// Every harmonic of a mesh up to the envelope's top (kSynchronousTopOrder, or the highest
// bearing line of the catalogue if above), and at least its first 8: a mesh's stiffness and load
// sharing vary with period 1/f_mesh, so the envelope of a healthy gearbox holds its whole comb. For
// the planetary mesh (just under one hss order on paper-2mw) 8 harmonics ended at 7.7 orders, and
// its comb teeth above (measured to the 50th on the full-order model's recordings) were read as
// bearing lines.
void add_mesh_harmonics(const Catalogue& catalogue, std::vector<double>& out) {
  const double top = std::max(kSynchronousTopOrder, envelope_max_order(catalogue));
  for (const PartRate& m : catalogue.meshes) {
    if (!(m.order > 0.0)) continue;
    for (int h = 1; h <= 8 || h * m.order <= top; ++h) out.push_back(h * m.order);
  }
}

// Envelope peaks are sought off the mesh harmonics only: a shaft's harmonics there are an
// impact once per revolution, which a family names (build_catalogue), not noise to skip.
std::vector<double> mesh_harmonics(const Catalogue& catalogue) {
  std::vector<double> out;
  add_mesh_harmonics(catalogue, out);
  return out;
}
}  // namespace

std::vector<double> envelope_exclusions(const Catalogue& catalogue) {
  std::vector<double> out;
  add_mesh_harmonics(catalogue, out);
  for (const PartRate& s : catalogue.shafts)
    if (s.id != "planet" && s.order >= kSynchronousShaftOrder)
      for (int k = 1; k * s.order <= kSynchronousTopOrder; ++k) out.push_back(k * s.order);
  return out;
}

std::vector<double> spectrum_exclusions(const Catalogue& catalogue) {
  std::vector<double> out = envelope_exclusions(catalogue);
  for (const Family& f : catalogue.families)
    if (f.domain == Domain::kSpectrum) out.insert(out.end(), f.orders.begin(), f.orders.end());
  return out;
}

const std::vector<double>* bearing_exclusions(const Hypothesis& h, const std::vector<double>& sync,
                                              const std::vector<double>& gears) {
  if (h.domain == Domain::kEnvelope) return &sync;
  return is_bearing(h.effect) ? &gears : nullptr;
}

LineMeasure measure_line(const OrderSpectrum& rec, const OrderSpectrum& sim, double order,
                         double tolerance, const LocateConfig& cfg,
                         const std::vector<double>* exclude) {
  LineMeasure m;
  m.order = order;
  if (rec.amplitude.empty() || !(order > 0.0)) return m;
  const double r = static_cast<double>(rec.revolutions);
  double best_order = order;
  // Searching among exclusions (the envelope's synchronous comb), only a line of its own
  // counts: a position where the tone is a local maximum. Next to an excluded line its
  // main lobe's flank (and, off-bin, its leakage) still reads high, falling away from it.
  const bool own_lines = tolerance > 0.0 && exclude != nullptr;
  double best = excluded(order, r, exclude) || own_lines ? 0.0 : rec.tone(order);
  if (tolerance > 0.0) {
    const auto k0 = static_cast<long long>(std::floor(order * (1.0 - tolerance) * r));
    const auto k1 = static_cast<long long>(std::ceil(order * (1.0 + tolerance) * r));
    for (long long k = std::max(1LL, k0); k <= k1; ++k) {
      const double o = static_cast<double>(k) / r;
      if (excluded(o, r, exclude)) continue;
      const double a = rec.tone(o);
      if (own_lines && (a < rec.tone(o - 1.0 / r) || a < rec.tone(o + 1.0 / r))) continue;
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
  m.significant = m.measured >= cfg.snr_min * m.noise &&
                  m.measured * m.measured >= cfg.excess_ratio * explained;
  if (!m.significant) m.excess = 0.0;
  return m;
}

namespace {

struct Peak {
  double order = 0.0;
  LineMeasure line;
  bool claimed = false;
};

// Significant excess peaks of a channel's spectrum up to max_order (none at `exclude`).
std::vector<Peak> excess_peaks(const OrderSpectrum& rec, const OrderSpectrum& sim, double max_order,
                               const LocateConfig& cfg,
                               const std::vector<double>* exclude = nullptr) {
  std::vector<Peak> peaks;
  const auto& a = rec.amplitude;
  if (a.size() < 8) return peaks;
  const double r = static_cast<double>(rec.revolutions);
  const std::size_t k_end = std::min(a.size() - 3, static_cast<std::size_t>(max_order * r));
  for (std::size_t k = std::max<std::size_t>(cfg.min_order_lines, 2); k <= k_end; ++k) {
    if (!(a[k] >= a[k - 1] && a[k] > a[k + 1] && a[k] >= a[k - 2] && a[k] > a[k + 2])) continue;
    const double o = static_cast<double>(k) / r;
    if (excluded(o, r, exclude)) continue;
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
    std::sort(mine.begin(), mine.end(),
              [](const Peak* a, const Peak* b) { return a->line.excess > b->line.excess; });
    feat.band_lo_hz = 1e300;
    for (const Peak* p : mine) {
      feat.excess += p->line.excess;
      feat.band_lo_hz = std::min(feat.band_lo_hz, p->order * ref_hz);
      feat.band_hi_hz = std::max(feat.band_hi_hz, p->order * ref_hz);
      feat.max_snr = std::max(feat.max_snr, p->line.measured / std::max(p->line.noise, 1e-300));
      if (feat.peaks_hz.size() < cfg.max_peaks_per_feature)
        feat.peaks_hz.push_back(p->order * ref_hz);
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
  std::sort(left.begin(), left.end(),
            [](const Peak* a, const Peak* b) { return a->line.excess > b->line.excess; });
  for (const Peak* p : left) {
    rest.excess += p->line.excess;
    rest.band_lo_hz = std::min(rest.band_lo_hz, p->order * ref_hz);
    rest.band_hi_hz = std::max(rest.band_hi_hz, p->order * ref_hz);
    rest.max_snr = std::max(rest.max_snr, p->line.measured / std::max(p->line.noise, 1e-300));
    if (rest.peaks_hz.size() < cfg.max_peaks_per_feature)
      rest.peaks_hz.push_back(p->order * ref_hz);
  }
  if (rest.excess >= 0.02 * total) {
    rest.share = rest.excess / total;
    out.push_back(std::move(rest));
  }
}

// Band amplification by a resonance: the lines the simulation has, compared in dB with
// the recording (gain g_i = 20·log10(m/s) about the channel's median gain), fitted by the
// transmissibility of a base-excited single-degree-of-freedom resonator
//   |H(f)| = sqrt((1 + (2ζr)²) / ((1 − r²)² + (2ζr)²)),  r = f/f_r,
// over a grid of f_r and ζ, within f_r/1.6 … 1.6·f_r. A band feature when the fit removes
// at least 60 % of the gains' squared deviation there, lines are amplified by ≥ 6 dB,
// and what is left scatters by less than 4 dB: a foreign gearbox's misfit is irregular
// from line to line, a resonance amplifies every line of its band along one curve.
void band_features(std::size_t channel, const OrderSpectrum& rec, const OrderSpectrum& sim,
                   double max_order, double ref_hz, double total, const LocateConfig& cfg,
                   std::vector<ResidualFeature>& out) {
  const auto& s = sim.amplitude;
  if (s.size() < 8 || rec.amplitude.size() < 8) return;
  struct G {
    double hz, gain_db, excess, snr;
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
    lines.push_back(
        {o * ref_hz, 20.0 * std::log10(m / sv), std::max(0.0, m * m - sv * sv - n * n), m / n});
  }
  if (lines.size() < 5) return;
  std::vector<double> gains;
  for (const G& g : lines) gains.push_back(g.gain_db);
  std::nth_element(gains.begin(), gains.begin() + static_cast<long>(gains.size() / 2), gains.end());
  const double median = gains[gains.size() / 2];
  auto transmissibility_db = [](double f, double fr, double zeta) {
    const double r = f / fr;
    const double num = 1.0 + (2.0 * zeta * r) * (2.0 * zeta * r);
    const double den = (1.0 - r * r) * (1.0 - r * r) + (2.0 * zeta * r) * (2.0 * zeta * r);
    return 10.0 * std::log10(num / den);
  };
  struct Best {
    double fr = 0.0, zeta = 0.0, improvement = 0.0, scatter = 0.0;
  } best;
  const double f_lo = lines.front().hz, f_hi = lines.back().hz;
  for (double fr = f_lo; fr <= f_hi; fr *= 1.01) {
    for (const double zeta : {0.01, 0.02, 0.04, 0.08}) {
      double null_rss = 0.0, fit_rss = 0.0;
      std::size_t in = 0, amplified = 0;
      for (const G& g : lines) {
        if (g.hz < fr / 1.6 || g.hz > fr * 1.6) continue;
        const double d = g.gain_db - median;
        const double t = transmissibility_db(g.hz, fr, zeta);
        null_rss += d * d;
        fit_rss += (d - t) * (d - t);
        ++in;
        if (t >= cfg.gain_db && d >= cfg.gain_db) ++amplified;
      }
      if (in < 5 || amplified < 2 || !(null_rss > 0.0)) continue;
      const double improvement = 1.0 - fit_rss / null_rss;
      if (improvement > best.improvement)
        best = {fr, zeta, improvement, std::sqrt(fit_rss / static_cast<double>(in))};
    }
  }
  if (best.improvement < 0.6 || best.scatter > 4.0) return;
  ResidualFeature f;
  f.channel = channel;
  f.domain = FeatureDomain::kBand;
  f.resonance_hz = best.fr;
  f.resonance_damping = best.zeta;
  f.fit_share = best.improvement;
  f.band_lo_hz = 1e300;
  std::vector<const G*> mine;
  double gsum = 0.0;
  for (const G& g : lines) {
    if (transmissibility_db(g.hz, best.fr, best.zeta) < 3.0 || g.hz < best.fr / 1.6 ||
        g.hz > best.fr * 1.6)
      continue;
    mine.push_back(&g);
    f.band_lo_hz = std::min(f.band_lo_hz, g.hz);
    f.band_hi_hz = std::max(f.band_hi_hz, g.hz);
    f.excess += g.excess;
    gsum += g.gain_db - median;
    f.max_snr = std::max(f.max_snr, g.snr);
    f.strength += g.gain_db > median ? (g.gain_db - median) * std::log(10.0) / 10.0 : 0.0;
  }
  if (mine.empty()) return;
  std::sort(mine.begin(), mine.end(), [](const G* a, const G* b) { return a->excess > b->excess; });
  for (const G* g : mine)
    if (f.peaks_hz.size() < cfg.max_peaks_per_feature) f.peaks_hz.push_back(g->hz);
  f.gain_db = gsum / static_cast<double>(mine.size());
  f.share = total > 0.0 ? std::min(1.0, f.excess / total) : 0.0;
  out.push_back(std::move(f));
}

}  // namespace

LocateResult locate(const Catalogue& cat, const std::vector<ChannelPair>& channels,
                    const LocateConfig& cfg) {
  LocateResult result;
  const std::vector<double> sync = envelope_exclusions(cat);
  const std::vector<double> gears = spectrum_exclusions(cat);
  const std::vector<double> meshes = mesh_harmonics(cat);
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
                   static_cast<double>(rec.spectrum.revolutions), ref_hz, result.spectrum_total[c],
                   cfg, result.features);
    band_features(c, rec.spectrum, sim.spectrum, rec.max_order, ref_hz, result.spectrum_total[c],
                  cfg, result.features);
    if (!rec.envelope.amplitude.empty()) {
      const double env_top = static_cast<double>(rec.envelope.amplitude.size() - 1) /
                             static_cast<double>(rec.envelope.revolutions) * 0.9;
      std::vector<Peak> ep = excess_peaks(rec.envelope, sim.envelope, env_top, cfg, &meshes);
      for (const Peak& p : ep) result.envelope_total[c] += p.line.excess;
      claim_families(cat, c, Domain::kEnvelope, FeatureDomain::kEnvelope, ep,
                     static_cast<double>(rec.envelope.revolutions), ref_hz,
                     result.envelope_total[c], cfg, result.features);
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
      for (std::size_t c = 0; c < channels.size(); ++c) {
        if (channels[c].location != h.location) continue;
        for (const ResidualFeature& f : result.features)
          if (f.channel == c && f.domain == FeatureDomain::kBand &&
              f.fit_share * f.strength > s.score) {
            s.share = f.fit_share;
            s.presence = 1.0;
            s.strength = f.strength;
            s.evidence = cfg.min_evidence;
            s.best_channel = c;
            s.score = f.fit_share * f.strength;
          }
      }
    } else {
      const bool env = h.domain == Domain::kEnvelope;
      const Family& fam = cat.families[h.family];
      double explained = 0.0, local = 0.0, weight = 0.0;
      for (const SignatureLine& l : h.lines) weight += l.weight;
      for (std::size_t c = 0; c < channels.size(); ++c) {
        const ChannelAnalysis& rec = *channels[c].recorded;
        const ChannelAnalysis& sim = *channels[c].simulated;
        const OrderSpectrum& rs = env ? rec.envelope : rec.spectrum;
        const OrderSpectrum& ss = env ? sim.envelope : sim.spectrum;
        if (rs.amplitude.empty()) continue;
        const double revs = static_cast<double>(rs.revolutions);
        const double top = static_cast<double>(rs.amplitude.size() - 3) / revs;
        auto usable = [&](double order, double tol) {
          return order * (1.0 + tol) <= top &&
                 order * revs >= static_cast<double>(cfg.min_order_lines);
        };
        double present = 0.0;
        std::vector<double> seen;  // positions counted in the local total
        for (const SignatureLine& l : h.lines) {
          if (!usable(l.order, h.tolerance)) continue;
          const LineMeasure m =
              measure_line(rs, ss, l.order, h.tolerance, cfg, bearing_exclusions(h, sync, gears));
          if (!m.significant) continue;
          explained += l.weight * m.excess;
          present += l.weight;
          s.evidence += l.weight * (m.measured * m.measured) / std::max(m.noise * m.noise, 1e-300);
          s.strength +=
              l.weight * std::log(m.measured * m.measured /
                                  std::max(m.simulated * m.simulated + m.noise * m.noise, 1e-300));
        }
        // The local total: the excess on the lines of its broad family and its own.
        std::vector<double> orders = fam.orders;
        for (const SignatureLine& l : h.lines) orders.push_back(l.order);
        for (double o : orders) {
          if (!usable(o, h.tolerance)) continue;
          const LineMeasure m =
              measure_line(rs, ss, o, h.tolerance, cfg, bearing_exclusions(h, sync, gears));
          if (!m.significant) continue;
          bool dup = false;
          for (double q : seen)
            if (std::abs(q - m.order) * revs < 1.5) dup = true;
          if (dup) continue;
          seen.push_back(m.order);
          local += m.excess;
        }
        if (weight > 0.0 && present / weight > s.presence) {
          s.presence = present / weight;
          s.best_channel = c;
        }
      }
      s.share = local > 0.0 ? std::min(1.0, explained / local) : 0.0;
      s.score = s.evidence >= cfg.min_evidence ? s.share * std::sqrt(s.presence) * s.strength : 0.0;
    }
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
      std::snprintf(buf, sizeof buf,
                    "lines amplified by %.1f dB over %.0f–%.0f Hz at the sensor on %s: a resonance",
                    f.gain_db, f.band_lo_hz, f.band_hi_hz,
                    f.channel < channels.size() ? channels[f.channel].location.c_str() : "?");
      return buf;
    case FeatureDomain::kAverage:
      std::snprintf(buf, sizeof buf,
                    "impulsive once per %s revolution in its synchronous average "
                    "(difference-signal kurtosis %.1f)",
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
    std::snprintf(buf, sizeof buf, ", in the envelope of %.0f–%.0f Hz", rec->band.f_lo_hz,
                  rec->band.f_hi_hz);
    text += buf;
  }
  return text;
}

}  // namespace model::diagnosis
