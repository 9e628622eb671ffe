#include "model/diagnosis/analysis.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

namespace model::diagnosis {

std::size_t samples_per_rev_for(double fs_hz, double slowest_ref_hz) {
  return std::bit_ceil(static_cast<std::size_t>(std::ceil(fs_hz / slowest_ref_hz)));
}

double envelope_max_order(const Catalogue& catalogue) {
  double top = 0.0;
  for (const Hypothesis& h : catalogue.hypotheses) {
    if (h.domain != Domain::kEnvelope) continue;
    for (const SignatureLine& l : h.lines) top = std::max(top, l.order * (1.0 + h.tolerance));
  }
  return top;
}

bool analyse_channel(const double* x, std::size_t n, double fs_hz, const AngleMap& map,
                     const AnalysisWindow& window, const Catalogue& catalogue,
                     const AnalysisConfig& config, double env_max_order, const KurtogramBand* band,
                     ChannelAnalysis& out, const WhiteningReference* whiten_as) {
  if (!map.valid() || window.revs < 8) return false;
  // The window's time span and slowest speed.
  const double t0 = map.time_at(window.start_rev);
  const double t1 = map.time_at(window.start_rev + static_cast<double>(window.revs));
  double slowest = 1e300;
  for (std::size_t r = 0; r < window.revs; ++r) {
    const double a = map.time_at(window.start_rev + static_cast<double>(r));
    const double b = map.time_at(window.start_rev + static_cast<double>(r + 1));
    slowest = std::min(slowest, 1.0 / (b - a));
  }
  const double mean_hz = static_cast<double>(window.revs) / (t1 - t0);
  const auto i0 = static_cast<std::size_t>(std::max(0.0, std::floor(t0 * fs_hz) - 4.0));
  const auto i1 = std::min(n, static_cast<std::size_t>(std::ceil(t1 * fs_hz) + 4.0));
  if (i1 <= i0 + 16) return false;
  out.stats = statistics(x + i0, i1 - i0);
  out.max_order = config.max_frequency_hz / mean_hz;

  // Order spectrum of the waveform.
  const std::size_t spr = samples_per_rev_for(fs_hz, slowest);
  if (!order_spectrum(x, n, fs_hz, map, 1.0, window.start_rev, spr, window.revs, out.spectrum))
    return false;

  // Band where impacts ring: kurtogram of the prewhitened window (or the given band).
  // A recording is whitened by itself (its filter kept when the kurtogram runs on it); a
  // simulation given `whiten_as` by the recording's filter.
  const bool like = config.prewhiten && whiten_as != nullptr && whiten_as->valid();
  out.whitening = {};
  std::vector<double> w;
  if (!config.prewhiten)
    w.assign(x + i0, x + i1);
  else if (like)
    w = whiten_like(x + i0, i1 - i0, fs_hz, *whiten_as);
  else if (band == nullptr)
    w = cepstral_prewhiten(x + i0, i1 - i0, fs_hz, out.whitening);
  else
    w = cepstral_prewhiten(x + i0, i1 - i0);
  const double env_hz = std::max(env_max_order, 1.0) * mean_hz * 1.05;
  if (band != nullptr) {
    out.band = *band;
    out.kurtogram = {};
  } else {
    KurtogramConfig kc;
    // Bands must be wide enough to carry the envelope lines as sidebands of their carrier.
    kc.max_level = config.kurtogram_max_level;
    while (kc.max_level > 0 && fs_hz / 2.0 / std::exp2(kc.max_level) < 2.0 * env_hz) --kc.max_level;
    kc.min_bandwidth_hz = 2.0 * env_hz;
    // Away from the prewhitened record's tapered ends.
    const auto edge = static_cast<std::size_t>(2.0 * kCpwTaper * static_cast<double>(w.size()));
    out.kurtogram = kurtogram(w.data() + edge, w.size() - 2 * edge, fs_hz, kc);
    const double ceiling =
        config.band_max_hz > 0.0 ? std::min(config.band_max_hz, fs_hz / 2.0) : fs_hz / 2.0;
    out.band = {};
    out.band.kurtosis = -1e300;
    for (const KurtogramBand& b : out.kurtogram.bands)
      if (b.f_hi_hz <= ceiling * 1.0000001 && b.kurtosis > out.band.kurtosis) out.band = b;
    if (out.band.f_hi_hz <= 0.0) out.band = {0.0, 0.0, ceiling, 0.0};
  }
  // Squared envelope in the band, normalised by its mean, low-passed and order-tracked.
  std::vector<double> env = squared_envelope(w.data(), w.size(), fs_hz, out.band.f_lo_hz,
                                             std::min(out.band.f_hi_hz, fs_hz / 2.0));
  double mean = 0.0;
  if (like) {
    // The mean a record of this length whitened by itself would have: its bins all of unit
    // magnitude, whatever their content (so the simulation's lines keep their strength
    // against the recording's whitened floor, not against its own).
    const std::vector<double> unit = cepstral_prewhiten(x + i0, i1 - i0);
    for (double v : squared_envelope(unit.data(), unit.size(), fs_hz, out.band.f_lo_hz,
                                     std::min(out.band.f_hi_hz, fs_hz / 2.0)))
      mean += v;
  } else {
    for (double v : env) mean += v;
  }
  mean /= static_cast<double>(std::max<std::size_t>(env.size(), 1));
  if (mean > 0.0)
    for (double& v : env) v /= mean;
  const std::size_t spr_env =
      std::bit_ceil(static_cast<std::size_t>(std::ceil(4.0 * std::max(env_max_order, 4.0))));
  env = lowpass(env.data(), env.size(), fs_hz, 0.45 * static_cast<double>(spr_env) * slowest);
  // The window as a map of its own: the envelope buffer starts at sample i0.
  std::vector<double> shifted = map.pulses();
  for (double& t : shifted) t -= static_cast<double>(i0) / fs_hz;
  const AngleMap local = AngleMap::from_pulses(std::move(shifted));
  if (!order_spectrum(env.data(), env.size(), fs_hz, local, 1.0, window.start_rev, spr_env,
                      window.revs, out.envelope)) {
    out.envelope = {};
  }

  // Synchronous averages of the shafts that carry gears of parallel stages.
  out.averages.clear();
  if (config.synchronous_averages) {
    for (const PartRate& s : catalogue.shafts) {
      if (s.id == "planet") continue;
      ShaftAverage a;
      a.shaft = s.id;
      a.order = s.order;
      const double start = std::ceil(window.start_rev * s.order);
      const double end = (window.start_rev + static_cast<double>(window.revs)) * s.order;
      const auto revs = static_cast<std::size_t>(std::max(0.0, std::floor(end - start)));
      if (revs < 4) continue;
      // Meshes synchronous with this shaft (a gear of theirs sits on it): a whole number
      // of mesh cycles per shaft revolution, its tooth count.
      SeparationSpec spec;
      for (const PartRate& m : catalogue.meshes) {
        const double per_rev = m.order / s.order;
        if (std::abs(per_rev - std::round(per_rev)) < 1e-6 && per_rev >= 4.0)
          spec.mesh_orders.push_back(static_cast<int>(std::lround(per_rev)));
      }
      if (spec.mesh_orders.empty()) continue;
      const std::size_t spr_s = std::min<std::size_t>(
          std::bit_ceil(static_cast<std::size_t>(std::ceil(fs_hz / (slowest * s.order)))),
          std::size_t{1} << 16);
      if (synchronous_average(x, n, fs_hz, map, s.order, start, spr_s, revs, spec, a.tsa))
        out.averages.push_back(std::move(a));
    }
  }
  return true;
}

void add_band_residual(const OrderSpectrum& rec, const OrderSpectrum& sim, std::size_t last,
                       double& miss, double& total) {
  if (rec.amplitude.empty()) return;
  last = std::min(last, rec.amplitude.size() - 1);
  const double ratio = std::exp2(1.0 / 12.0);
  for (std::size_t k0 = 1; k0 <= last;) {
    const std::size_t k1 = std::min(
        last + 1,
        std::max(k0 + 8, static_cast<std::size_t>(std::ceil(static_cast<double>(k0) * ratio))));
    double em = 0.0, es = 0.0;
    for (std::size_t k = k0; k < k1; ++k) {
      em += rec.amplitude[k] * rec.amplitude[k];
      const double a_s = k < sim.amplitude.size() ? sim.amplitude[k] : 0.0;
      es += a_s * a_s;
    }
    const double d = std::sqrt(em) - std::sqrt(es);
    miss += d * d;
    total += em;
    k0 = k1;
  }
}

void add_window_residual(const OrderSpectrum& rec, const OrderSpectrum& sim,
                         const std::vector<std::size_t>& lines, double& miss, double& total) {
  double em = 0.0, es = 0.0;
  bool open = false;
  std::size_t prev = 0;
  auto close_run = [&] {
    const double d = std::sqrt(em) - std::sqrt(es);
    miss += d * d;
    total += em;
    em = es = 0.0;
  };
  for (std::size_t k : lines) {
    if (k >= rec.amplitude.size()) continue;
    if (open && k != prev + 1) close_run();
    em += rec.amplitude[k] * rec.amplitude[k];
    const double a_s = k < sim.amplitude.size() ? sim.amplitude[k] : 0.0;
    es += a_s * a_s;
    prev = k;
    open = true;
  }
  if (open) close_run();
}

}  // namespace model::diagnosis
