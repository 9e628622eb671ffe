#include "model/dsp/order_tracking.hpp"

#include <algorithm>
#include <cmath>

namespace model::dsp {

OrderTracker::OrderTracker(std::size_t samples_per_rev, std::size_t revolutions,
                           std::size_t max_pulses)
    : samples_per_rev_(samples_per_rev),
      revolutions_(revolutions),
      pulse_times_(max_pulses, 0.0),
      max_pulses_(max_pulses) {}

std::size_t OrderTracker::detect_pulses(const double* tacho, std::size_t n, double fs_hz) {
  if (n < 2 || !(fs_hz > 0.0)) return 0;
  double lo = tacho[0];
  double hi = tacho[0];
  for (std::size_t i = 0; i < n; ++i) {
    lo = std::min(lo, tacho[i]);
    hi = std::max(hi, tacho[i]);
  }
  if (!(hi > lo)) return 0;
  const double mid = 0.5 * (lo + hi);
  const double rearm = lo + 0.25 * (hi - lo);
  bool armed = tacho[0] < rearm;
  std::size_t count = 0;
  for (std::size_t i = 1; i < n && count < max_pulses_; ++i) {
    if (tacho[i] < rearm) armed = true;
    if (armed && tacho[i - 1] < mid && tacho[i] >= mid) {
      const double frac = (mid - tacho[i - 1]) / (tacho[i] - tacho[i - 1]);
      pulse_times_[count++] = (static_cast<double>(i - 1) + frac) / fs_hz;
      armed = false;
    }
  }
  return count;
}

namespace {
// Catmull–Rom cubic through x[i−1..i+2] at i + u, u in [0, 1).
double cubic_at(const double* x, std::size_t i, double u) {
  const double p0 = x[i - 1], p1 = x[i], p2 = x[i + 1], p3 = x[i + 2];
  return p1 + 0.5 * u *
                  (p2 - p0 +
                   u * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3 + u * (3.0 * (p1 - p2) + p3 - p0)));
}
}  // namespace

DspStatus OrderTracker::resample(const double* x, std::size_t n, double fs_hz,
                                 const SpeedReference& speed, double* out) const {
  const bool use_pulses = speed.pulse_times_s != nullptr && speed.pulses >= 2;
  if (!(fs_hz > 0.0) || (!use_pulses && !(speed.shaft_hz > 0.0))) return DspStatus::kNoSpeed;
  if (use_pulses && speed.pulses < revolutions_ + 1) return DspStatus::kTooShort;
  const double t0 = use_pulses ? speed.pulse_times_s[0] : 1.0 / fs_hz;
  const double t_end = use_pulses ? speed.pulse_times_s[revolutions_]
                                  : t0 + static_cast<double>(revolutions_) / speed.shaft_hz;
  // The last sample used by the cubic is floor(t·fs) + 2.
  if (n < 4 || t_end * fs_hz + 2.0 >= static_cast<double>(n) || t0 * fs_hz < 1.0)
    return DspStatus::kTooShort;
  const double inv_spr = 1.0 / static_cast<double>(samples_per_rev_);
  for (std::size_t rev = 0; rev < revolutions_; ++rev) {
    const double ta =
        use_pulses ? speed.pulse_times_s[rev] : t0 + static_cast<double>(rev) / speed.shaft_hz;
    const double tb = use_pulses ? speed.pulse_times_s[rev + 1]
                                 : t0 + static_cast<double>(rev + 1) / speed.shaft_hz;
    for (std::size_t j = 0; j < samples_per_rev_; ++j) {
      // Speed constant within one revolution: angle linear in time between pulses.
      const double t = ta + (tb - ta) * static_cast<double>(j) * inv_spr;
      const double s = t * fs_hz;
      const auto i = static_cast<std::size_t>(s);
      out[rev * samples_per_rev_ + j] = cubic_at(x, i, s - static_cast<double>(i));
    }
  }
  return DspStatus::kOk;
}

std::optional<double> estimate_shaft_hz_from_mesh(const double* x, std::size_t n, double fs_hz,
                                                  double nominal_shaft_hz, double mesh_order,
                                                  double search, SpectrumAnalyzer& analyzer,
                                                  double* work) {
  if (!analyzer.valid() || n < analyzer.size() || !(fs_hz > 0.0) || !(nominal_shaft_hz > 0.0) ||
      !(mesh_order > 0.0)) {
    return std::nullopt;
  }
  analyzer.amplitude_spectrum(x, work);
  const double df = fs_hz / static_cast<double>(analyzer.size());
  const double f_nominal = mesh_order * nominal_shaft_hz;
  const auto k_lo =
      static_cast<std::size_t>(std::max(3.0, std::floor(f_nominal * (1.0 - search) / df)));
  const auto k_hi = static_cast<std::size_t>(std::ceil(f_nominal * (1.0 + search) / df));
  if (k_hi + 2 >= analyzer.lines() || k_lo >= k_hi) return std::nullopt;
  std::size_t k_peak = k_lo;
  for (std::size_t k = k_lo; k <= k_hi; ++k) {
    if (work[k] > work[k_peak]) k_peak = k;
  }
  double weight = 0.0;
  double moment = 0.0;
  for (std::size_t k = k_peak - 2; k <= k_peak + 2; ++k) {
    const double e = work[k] * work[k];
    weight += e;
    moment += e * static_cast<double>(k);
  }
  if (!(weight > 0.0)) return std::nullopt;
  return moment / weight * df / mesh_order;
}

}  // namespace model::dsp
