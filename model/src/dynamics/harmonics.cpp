#include "model/dynamics/harmonics.hpp"

#include <cmath>
#include <numbers>

namespace model::dynamics {

double mean(std::span<const double> x) {
  if (x.empty()) return 0.0;
  double s = 0.0;
  for (double v : x) s += v;
  return s / static_cast<double>(x.size());
}

double rms_about_mean(std::span<const double> x) {
  if (x.empty()) return 0.0;
  const double m = mean(x);
  double s = 0.0;
  for (double v : x) s += (v - m) * (v - m);
  return std::sqrt(s / static_cast<double>(x.size()));
}

double line_amplitude(std::span<const double> x, double sample_rate_hz, double frequency_hz) {
  const std::size_t n = x.size();
  if (n < 2) return 0.0;
  const double m = mean(x);
  const double w = 2.0 * std::numbers::pi * frequency_hz / sample_rate_hz;
  const double wn = 2.0 * std::numbers::pi / static_cast<double>(n - 1);
  // Rotate phasors (signal frequency and Hann window) instead of calling sin/cos per
  // sample; re-normalise against drift.
  double c = 1.0, s = 0.0;
  const double dc = std::cos(w), ds = std::sin(w);
  double hc = 1.0, hs = 0.0;
  const double dhc = std::cos(wn), dhs = std::sin(wn);
  double re = 0.0, im = 0.0, wsum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double win = 0.5 * (1.0 - hc);
    const double hc2 = hc * dhc - hs * dhs;
    hs = hs * dhc + hc * dhs;
    hc = hc2;
    const double v = (x[i] - m) * win;
    re += v * c;
    im -= v * s;
    wsum += win;
    const double c2 = c * dc - s * ds;
    s = s * dc + c * ds;
    c = c2;
    if ((i & 1023u) == 1023u) {
      const double norm = std::sqrt(c * c + s * s);
      c /= norm;
      s /= norm;
      const double hnorm = std::sqrt(hc * hc + hs * hs);
      hc /= hnorm;
      hs /= hnorm;
    }
  }
  return 2.0 * std::sqrt(re * re + im * im) / wsum;
}

}  // namespace model::dynamics
