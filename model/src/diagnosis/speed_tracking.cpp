#include "model/diagnosis/speed_tracking.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <numbers>

namespace model::diagnosis {

namespace {

constexpr double kPi = std::numbers::pi;

// Short-time spectra of x: Hann frames of `frame` samples, hop frame/2, zero-padded to
// 4·frame; calls visit(centre_s, magnitudes) per frame.
template <typename Visit>
void stft(const double* x, std::size_t n, double fs, std::size_t frame, Visit&& visit) {
  const std::size_t nfft = 4 * frame;
  const Fft fft(nfft);
  std::vector<double> w(frame);
  for (std::size_t i = 0; i < frame; ++i)
    w[i] = 0.5 * (1.0 - std::cos(2.0 * kPi * static_cast<double>(i) / static_cast<double>(frame)));
  std::vector<Complex> in(nfft), out(nfft);
  std::vector<double> mag(nfft / 2 + 1);
  for (std::size_t start = 0; start + frame <= n; start += frame / 2) {
    double mean = 0.0;
    for (std::size_t i = 0; i < frame; ++i) mean += x[start + i];
    mean /= static_cast<double>(frame);
    std::fill(in.begin(), in.end(), Complex(0.0, 0.0));
    for (std::size_t i = 0; i < frame; ++i) in[i] = Complex((x[start + i] - mean) * w[i], 0.0);
    fft.forward(in.data(), out.data());
    for (std::size_t k = 0; k <= nfft / 2; ++k) mag[k] = std::abs(out[k]);
    visit((static_cast<double>(start) + 0.5 * static_cast<double>(frame)) / fs, mag);
  }
}

double median_of(std::vector<double> v) {
  if (v.empty()) return 0.0;
  auto mid = v.begin() + static_cast<long>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// Peak of mag within [k0, k1], refined by a parabola through the log amplitudes.
double peak_line(const std::vector<double>& mag, std::size_t k0, std::size_t k1) {
  std::size_t kp = k0;
  for (std::size_t k = k0; k <= k1; ++k)
    if (mag[k] > mag[kp]) kp = k;
  if (kp == 0 || kp + 1 >= mag.size()) return static_cast<double>(kp);
  const double a = std::log(std::max(mag[kp - 1], 1e-300));
  const double b = std::log(std::max(mag[kp], 1e-300));
  const double c = std::log(std::max(mag[kp + 1], 1e-300));
  const double den = a - 2.0 * b + c;
  const double d = den < 0.0 ? 0.5 * (a - c) / den : 0.0;
  return static_cast<double>(kp) + std::clamp(d, -0.5, 0.5);
}

// Integer-revolution instants of the angle θ(t) = ∫ f(t) dt, f linear between the
// knots (t_k, f_k) and constant outside, θ(0) = 0.
std::vector<double> pulses_from_speed(const std::vector<double>& t, const std::vector<double>& f,
                                      double t_end) {
  std::vector<double> pulses;
  if (t.empty()) return pulses;
  auto speed = [&](double tt) {
    if (tt <= t.front()) return f.front();
    if (tt >= t.back()) return f.back();
    const auto it = std::upper_bound(t.begin(), t.end(), tt);
    const auto i = static_cast<std::size_t>(it - t.begin()) - 1;
    const double u = (tt - t[i]) / (t[i + 1] - t[i]);
    return f[i] + u * (f[i + 1] - f[i]);
  };
  const double dt = 1e-3;
  double theta = 0.0;
  double next = 1.0;
  pulses.push_back(0.0);
  for (double tt = 0.0; tt < t_end; tt += dt) {
    const double f0 = speed(tt), f1 = speed(tt + dt);
    const double step = 0.5 * (f0 + f1) * dt;
    while (theta + step >= next) {
      // Within the step the angle is nearly linear: interpolate the crossing.
      pulses.push_back(tt + (next - theta) / step * dt);
      next += 1.0;
    }
    theta += step;
  }
  return pulses;
}

// One phase-demodulation pass: the angle map corrected by the phase of the line
// `order` within ±band orders, in the angle domain of `map`.
bool refine(const double* x, std::size_t n, double fs, const AngleMap& map, double order,
            double band, AngleMap& refined) {
  const double f_min_hz = map.mean_hz() * 0.95;
  const std::size_t spr = std::bit_ceil(static_cast<std::size_t>(std::ceil(fs / f_min_hz)));
  const double start = std::ceil(map.revolutions_at(2.0 / fs));
  const std::size_t avail = revolutions_available(n, fs, map, 1.0, start);
  const std::size_t revs = fft_size_at_most(avail);
  if (revs < 8) return false;
  std::vector<double> a;
  if (!resample_to_angle(x, n, fs, map, 1.0, start, spr, revs, a)) return false;
  const std::size_t m = a.size();
  const Fft fft(m);
  std::vector<Complex> in(m), spec(m);
  for (std::size_t i = 0; i < m; ++i) in[i] = Complex(a[i], 0.0);
  fft.forward(in.data(), spec.data());
  const double r = static_cast<double>(revs);
  const auto k_lo = static_cast<std::size_t>(std::ceil((order - band) * r));
  const auto k_hi = static_cast<std::size_t>(std::floor((order + band) * r));
  if (k_hi <= k_lo + 1 || 2 * k_hi >= m) return false;
  std::fill(in.begin(), in.end(), Complex(0.0, 0.0));
  for (std::size_t k = k_lo; k <= k_hi; ++k) in[k] = 2.0 * spec[k];
  std::vector<Complex> z(m);
  fft.inverse(in.data(), z.data());
  // Unwrapped phase minus the coarse angle's phase: the angle correction δ [rev].
  std::vector<double> delta(m);
  double prev = std::arg(z[0]);
  double unwrapped = prev;
  double sum = 0.0;
  for (std::size_t i = 0; i < m; ++i) {
    const double ph = std::arg(z[i]);
    double d = ph - prev;
    d -= 2.0 * kPi * std::round(d / (2.0 * kPi));
    unwrapped += d;
    prev = ph;
    const double theta0 = static_cast<double>(i) / static_cast<double>(spr);
    delta[i] = unwrapped / (2.0 * kPi * order) - theta0;
    sum += delta[i];
  }
  const double mean = sum / static_cast<double>(m);
  for (double& d : delta) d -= mean;
  // The ideal band filter rings near the ends of the block: skip 1/band revolutions there.
  const double trim = std::ceil(1.0 / band);
  auto delta_at = [&](double theta0) {  // theta0 relative to `start`
    const double pos =
        std::clamp(theta0 * static_cast<double>(spr), 0.0, static_cast<double>(m - 1));
    const auto i = std::min(static_cast<std::size_t>(pos), m - 2);
    const double u = pos - static_cast<double>(i);
    return delta[i] + u * (delta[i + 1] - delta[i]);
  };
  std::vector<double> pulses;
  for (double k = trim; k <= r - trim; k += 1.0) {
    // θ_true(θ0) = θ0 + δ(θ0) = k  →  θ0 by fixed-point iteration (δ varies slowly).
    double theta0 = k;
    for (int it = 0; it < 4; ++it) theta0 = k - delta_at(theta0);
    pulses.push_back(map.time_at(start + theta0));
  }
  if (pulses.size() < 8) return false;
  AngleMap next = AngleMap::from_pulses(std::move(pulses));
  if (!next.valid()) return false;
  refined = std::move(next);
  return true;
}

}  // namespace

TrackedSpeed track_speed(const double* x, std::size_t n, double fs_hz, double nominal_hz,
                         const std::vector<LineCandidate>& candidates,
                         const SpeedTrackingConfig& config) {
  TrackedSpeed result;
  if (n < 1024 || !(fs_hz > 0.0) || !(nominal_hz > 0.0) || candidates.empty()) return result;
  const double duration = static_cast<double>(n) / fs_hz;
  const double approx_revs = duration * nominal_hz;

  // 1. Line choice on the averaged spectrum of a common frame length.
  struct Choice {
    double order = 0.0, spacing = 0.0, prominence = 0.0;
    std::size_t frame = 0;
  };
  Choice best;
  const std::size_t max_frame =
      std::bit_ceil(static_cast<std::size_t>(config.max_frame_s * fs_hz)) / 2;
  const std::size_t base_frame = std::min<std::size_t>(
      max_frame,
      std::max<std::size_t>(1024, std::bit_ceil(static_cast<std::size_t>(0.25 * fs_hz))));
  std::vector<double> avg;
  std::size_t frames = 0;
  stft(x, n, fs_hz, std::min(base_frame, std::bit_ceil(n) / 2),
       [&](double, const std::vector<double>& mag) {
         if (avg.empty()) avg.assign(mag.size(), 0.0);
         for (std::size_t k = 0; k < mag.size(); ++k) avg[k] += mag[k];
         ++frames;
       });
  if (frames == 0) return result;
  const double df_avg = fs_hz / static_cast<double>(2 * (avg.size() - 1));
  for (const LineCandidate& c : candidates) {
    const double f = c.order * nominal_hz;
    if (!(c.order > 0.0) || f * (1.0 + 3.0 * config.search) > 0.45 * fs_hz) continue;
    // The final demodulation band must span a few lines of the whole record, and the
    // STFT must separate the line from its neighbours within one frame of ≤ max_frame_s.
    const double band = config.band_share * c.spacing;
    if (band * approx_revs < 3.0) continue;
    // Hann main lobe ±2/T: neighbours 2/T apart are resolved.
    const double needed_frame_s = 2.0 / (c.spacing * nominal_hz);
    if (needed_frame_s > config.max_frame_s || needed_frame_s > duration / 4.0) continue;
    const auto k0 = static_cast<std::size_t>(f * (1.0 - config.search) / df_avg);
    const auto k1 = static_cast<std::size_t>(f * (1.0 + config.search) / df_avg) + 1;
    const auto w0 =
        static_cast<std::size_t>(std::max(1.0, f * (1.0 - 4.0 * config.search) / df_avg));
    const auto w1 = std::min(
        avg.size() - 1, static_cast<std::size_t>(f * (1.0 + 4.0 * config.search) / df_avg) + 1);
    if (k1 >= avg.size() || k0 >= k1) continue;
    double peak = 0.0;
    for (std::size_t k = k0; k <= k1; ++k) peak = std::max(peak, avg[k]);
    std::vector<double> around(avg.begin() + static_cast<long>(w0),
                               avg.begin() + static_cast<long>(w1) + 1);
    const double floor = median_of(std::move(around));
    const double prominence = floor > 0.0 ? peak / floor : 0.0;
    if (prominence > best.prominence) {
      best = {c.order, c.spacing, prominence,
              std::max<std::size_t>(
                  1024, std::bit_ceil(static_cast<std::size_t>(needed_frame_s * fs_hz)))};
    }
  }
  if (best.prominence < config.min_prominence) return result;

  // 2. Coarse track of the chosen line.
  std::vector<double> t_knots, f_knots;
  const double f_nom = best.order * nominal_hz;
  stft(x, n, fs_hz, best.frame, [&](double centre, const std::vector<double>& mag) {
    const double df = fs_hz / static_cast<double>(2 * (mag.size() - 1));
    const auto k0 = static_cast<std::size_t>(std::max(1.0, f_nom * (1.0 - config.search) / df));
    const auto k1 =
        std::min(mag.size() - 2, static_cast<std::size_t>(f_nom * (1.0 + config.search) / df) + 1);
    t_knots.push_back(centre);
    f_knots.push_back(peak_line(mag, k0, k1) * df / best.order);
  });
  if (t_knots.size() < 2) return result;
  // A median of three removes single-frame outliers (a sideband or an impact taking the peak).
  std::vector<double> smooth = f_knots;
  for (std::size_t i = 1; i + 1 < f_knots.size(); ++i)
    smooth[i] = std::max(std::min(f_knots[i - 1], f_knots[i]),
                         std::min(std::max(f_knots[i - 1], f_knots[i]), f_knots[i + 1]));
  AngleMap map = AngleMap::from_pulses(pulses_from_speed(t_knots, smooth, duration));
  if (!map.valid()) return result;

  // 3. Phase-demodulation refinements.
  const double band = config.band_share * best.spacing;
  for (int i = 0; i < config.refinements; ++i) {
    AngleMap refined;
    if (!refine(x, n, fs_hz, map, best.order, band, refined)) break;
    map = std::move(refined);
  }

  result.ok = true;
  result.line_order = best.order;
  result.prominence = best.prominence;
  result.mean_hz = map.mean_hz();
  const auto& p = map.pulses();
  result.min_hz = 1e300;
  result.max_hz = 0.0;
  for (std::size_t i = 1; i < p.size(); ++i) {
    const double f = 1.0 / (p[i] - p[i - 1]);
    result.min_hz = std::min(result.min_hz, f);
    result.max_hz = std::max(result.max_hz, f);
  }
  result.map = std::move(map);
  return result;
}

}  // namespace model::diagnosis
