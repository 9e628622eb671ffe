#include "model/diagnosis/angle.hpp"

#include <algorithm>
#include <cmath>

namespace model::diagnosis {

AngleMap AngleMap::from_pulses(std::vector<double> pulse_times_s) {
  AngleMap m;
  for (std::size_t i = 1; i < pulse_times_s.size(); ++i) {
    if (!(pulse_times_s[i] > pulse_times_s[i - 1])) return m;  // invalid
  }
  if (pulse_times_s.size() >= 2) m.pulses_ = std::move(pulse_times_s);
  return m;
}

AngleMap AngleMap::constant(double shaft_hz, double t0_s) {
  AngleMap m;
  if (shaft_hz > 0.0) m.pulses_ = {t0_s, t0_s + 1.0 / shaft_hz};
  return m;
}

double AngleMap::revolutions_at(double t_s) const {
  if (!valid()) return 0.0;
  const std::size_t n = pulses_.size();
  if (t_s <= pulses_.front()) {
    return (t_s - pulses_[0]) / (pulses_[1] - pulses_[0]);
  }
  if (t_s >= pulses_.back()) {
    return static_cast<double>(n - 1) + (t_s - pulses_[n - 1]) / (pulses_[n - 1] - pulses_[n - 2]);
  }
  const auto it = std::upper_bound(pulses_.begin(), pulses_.end(), t_s);
  const auto i = static_cast<std::size_t>(it - pulses_.begin()) - 1;
  return static_cast<double>(i) + (t_s - pulses_[i]) / (pulses_[i + 1] - pulses_[i]);
}

double AngleMap::time_at(double revolutions) const {
  if (!valid()) return 0.0;
  const std::size_t n = pulses_.size();
  if (revolutions <= 0.0) return pulses_[0] + revolutions * (pulses_[1] - pulses_[0]);
  if (revolutions >= static_cast<double>(n - 1)) {
    return pulses_[n - 1] +
           (revolutions - static_cast<double>(n - 1)) * (pulses_[n - 1] - pulses_[n - 2]);
  }
  const auto i = static_cast<std::size_t>(revolutions);
  const double frac = revolutions - static_cast<double>(i);
  return pulses_[i] + frac * (pulses_[i + 1] - pulses_[i]);
}

double AngleMap::mean_hz() const {
  if (!valid()) return 0.0;
  return static_cast<double>(pulses_.size() - 1) / (pulses_.back() - pulses_.front());
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

std::size_t revolutions_available(std::size_t n, double fs_hz, const AngleMap& map, double ratio,
                                  double start_rev) {
  if (!map.valid() || !(fs_hz > 0.0) || !(ratio > 0.0) || n < 4) return 0;
  // Usable time span: the cubic needs samples i−1..i+2.
  const double t_last = (static_cast<double>(n) - 3.0) / fs_hz;
  const double t_first = 1.0 / fs_hz;
  if (map.time_at(start_rev / ratio) < t_first) return 0;
  const double end_rev = map.revolutions_at(t_last) * ratio;
  if (end_rev <= start_rev) return 0;
  return static_cast<std::size_t>(std::floor(end_rev - start_rev));
}

bool resample_to_angle(const double* x, std::size_t n, double fs_hz, const AngleMap& map,
                       double ratio, double start_rev, std::size_t spr, std::size_t revs,
                       std::vector<double>& out) {
  if (spr == 0 || revs == 0 || revolutions_available(n, fs_hz, map, ratio, start_rev) < revs)
    return false;
  out.resize(spr * revs);
  const double inv_spr = 1.0 / static_cast<double>(spr);
  for (std::size_t r = 0; r < revs; ++r) {
    for (std::size_t j = 0; j < spr; ++j) {
      const double shaft_rev =
          start_rev + static_cast<double>(r) + static_cast<double>(j) * inv_spr;
      const double s = map.time_at(shaft_rev / ratio) * fs_hz;
      auto i = static_cast<std::size_t>(s);
      i = std::clamp<std::size_t>(i, 1, n - 3);
      out[r * spr + j] = cubic_at(x, i, s - static_cast<double>(i));
    }
  }
  return true;
}

double OrderSpectrum::tone(double order) const { return lobe_amplitude(amplitude, line(order), 2); }

double OrderSpectrum::noise(double order) const {
  return lobe_noise_floor(amplitude, line(order), 2, 24);
}

bool order_spectrum(const double* x, std::size_t n, double fs_hz, const AngleMap& map, double ratio,
                    double start_rev, std::size_t spr, std::size_t revs, OrderSpectrum& out) {
  std::vector<double> angle;
  if (!resample_to_angle(x, n, fs_hz, map, ratio, start_rev, spr, revs, angle)) return false;
  const Fft fft(angle.size());
  out.revolutions = revs;
  out.samples_per_rev = spr;
  out.shaft_hz = map.mean_hz() * ratio;
  hann_amplitude_spectrum(angle.data(), angle.size(), fft, out.amplitude);
  return true;
}

bool synchronous_average(const double* x, std::size_t n, double fs_hz, const AngleMap& map,
                         double ratio, double start_rev, std::size_t spr, std::size_t revs,
                         const SeparationSpec& spec, SynchronousAverage& out) {
  std::vector<double> angle;
  if (!resample_to_angle(x, n, fs_hz, map, ratio, start_rev, spr, revs, angle)) return false;
  out.samples_per_rev = spr;
  out.revolutions = revs;
  out.average.assign(spr, 0.0);
  for (std::size_t r = 0; r < revs; ++r)
    for (std::size_t j = 0; j < spr; ++j) out.average[j] += angle[r * spr + j];
  for (double& v : out.average) v /= static_cast<double>(revs);
  // Separation in the order domain of one revolution: line k is shaft order k exactly.
  const Fft fft(spr);
  std::vector<Complex> in(spr), spec_avg(spr), work(spr);
  for (std::size_t j = 0; j < spr; ++j) in[j] = Complex(out.average[j], 0.0);
  fft.forward(in.data(), spec_avg.data());
  auto zero_order = [&](std::vector<Complex>& s, long long k) {
    if (k <= 0 || 2 * static_cast<std::size_t>(k) > spr) return;
    s[static_cast<std::size_t>(k)] = Complex(0.0, 0.0);
    s[spr - static_cast<std::size_t>(k)] = Complex(0.0, 0.0);
  };
  std::vector<Complex> res = spec_avg;
  res[0] = Complex(0.0, 0.0);
  for (int k = 1; k <= spec.low_orders; ++k) zero_order(res, k);
  for (const int mesh : spec.mesh_orders) {
    if (mesh <= 0) continue;
    for (long long h = mesh; 2 * static_cast<std::size_t>(h) <= spr; h += mesh) zero_order(res, h);
  }
  std::vector<Complex> diff = res;
  for (const int mesh : spec.mesh_orders) {
    if (mesh <= 0) continue;
    for (long long h = mesh; 2 * static_cast<std::size_t>(h) <= spr; h += mesh)
      for (int s = 1; s <= spec.sidebands; ++s) {
        zero_order(diff, h - s);
        zero_order(diff, h + s);
      }
  }
  auto back = [&](const std::vector<Complex>& s, std::vector<double>& dst) {
    fft.inverse(s.data(), work.data());
    dst.resize(spr);
    for (std::size_t j = 0; j < spr; ++j) dst[j] = work[j].real();
  };
  back(res, out.residual);
  back(diff, out.difference);
  out.average_stats = statistics(out.average.data(), spr);
  out.residual_stats = statistics(out.residual.data(), spr);
  out.difference_stats = statistics(out.difference.data(), spr);
  return true;
}

}  // namespace model::diagnosis
