// The angle domain: order tracking, synchronous averages and speed tracking without a
// tacho, against waveforms generated from a known shaft angle θ(t).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "model/diagnosis/angle.hpp"
#include "model/diagnosis/speed_tracking.hpp"

namespace {

namespace md = model::diagnosis;
constexpr double kPiRad = std::numbers::pi;

// A drifting shaft: f(t) = f0·(1 + d·sin(2πt/T + φ)), θ(t) = ∫f dt in closed form.
struct Drift {
  double f0 = 14.3, d = 0.02, period = 20.0, phase = 0.7;
  double theta(double t) const {
    const double w = 2.0 * kPiRad / period;
    return f0 * (t - d / w * (std::cos(w * t + phase) - std::cos(phase)));
  }
  double hz(double t) const { return f0 * (1.0 + d * std::sin(2.0 * kPiRad * t / period + phase)); }
};

std::vector<double> exact_pulses(const Drift& s, double duration) {
  std::vector<double> p;
  double t = 0.0;
  for (int k = 0;; ++k) {
    // Newton on θ(t) = k.
    for (int it = 0; it < 30; ++it) t -= (s.theta(t) - k) / s.hz(t);
    if (t > duration) break;
    p.push_back(t);
    t += 1.0 / s.f0;
  }
  return p;
}

TEST(AngleMap, InterpolatesBetweenPulsesAndInvertsItself) {
  const md::AngleMap m = md::AngleMap::from_pulses({0.1, 0.2, 0.35, 0.45});
  ASSERT_TRUE(m.valid());
  EXPECT_NEAR(m.revolutions_at(0.275), 1.5, 1e-12);
  EXPECT_NEAR(m.time_at(1.5), 0.275, 1e-12);
  EXPECT_NEAR(m.revolutions_at(0.05), -0.5, 1e-12);  // extrapolated with the first period
  EXPECT_NEAR(m.time_at(3.5), 0.5, 1e-12);           // and with the last
  EXPECT_NEAR(m.mean_hz(), 3.0 / 0.35, 1e-12);
  EXPECT_FALSE(md::AngleMap::from_pulses({0.1, 0.1}).valid());
}

TEST(OrderTracking, PutsAFrequencyModulatedLineBackOnItsOrder) {
  // x = cos(2π·26·θ(t)) with the speed drifting ±2 %: in time the line smears over
  // ±7 Hz; order-tracked with the exact pulses it is one line of amplitude 1 at order 26.
  const Drift s;
  const double fs = 25600.0, duration = 12.0;
  const auto n = static_cast<std::size_t>(duration * fs);
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i) x[i] = std::cos(2.0 * kPiRad * 26.0 * s.theta(i / fs));
  const md::AngleMap map = md::AngleMap::from_pulses(exact_pulses(s, duration));
  md::OrderSpectrum os;
  ASSERT_TRUE(md::order_spectrum(x.data(), n, fs, map, 1.0, 1.0, 2048, 160, os));
  EXPECT_NEAR(os.tone(26.0), 1.0, 2e-3);  // linear angle between pulses: 0.2 % left
  EXPECT_LT(os.tone(26.0 + 5.0 / 160.0), 2e-3);
  EXPECT_NEAR(os.shaft_hz, s.f0, 0.05 * s.f0);
}

TEST(SynchronousAverage, RecoversTheShaftPatternAndTheResidualShowsTheImpact) {
  // Pattern locked to a shaft turning 0.25 × the reference: a 20-tooth mesh tone plus a
  // short impact once per revolution, in Gaussian noise of RMS 1. The average over
  // R revolutions leaves noise of RMS 1/√R; the residual (mesh removed) is impulsive.
  const Drift s;
  const double fs = 25600.0, duration = 20.0, ratio = 0.25;
  const auto n = static_cast<std::size_t>(duration * fs);
  std::vector<double> x(n);
  std::mt19937_64 rng(2);
  std::normal_distribution<double> gauss(0.0, 1.0);
  auto pattern = [](double rev) {
    const double frac = rev - std::floor(rev);
    const double impact =
        frac > 0.5 && frac < 0.52 ? 1.5 * std::sin(kPiRad * (frac - 0.5) / 0.02) : 0.0;
    return 2.0 * std::cos(2.0 * kPiRad * 20.0 * rev) + impact;
  };
  for (std::size_t i = 0; i < n; ++i) x[i] = pattern(ratio * s.theta(i / fs)) + gauss(rng);
  const md::AngleMap map = md::AngleMap::from_pulses(exact_pulses(s, duration));
  md::SynchronousAverage tsa;
  md::SeparationSpec spec;
  spec.mesh_orders = {20};
  const std::size_t revs = md::revolutions_available(n, fs, map, ratio, 1.0);
  ASSERT_GE(revs, 60u);
  ASSERT_TRUE(md::synchronous_average(x.data(), n, fs, map, ratio, 1.0, 8192, revs, spec, tsa));
  double err = 0.0;
  for (std::size_t j = 0; j < 8192; ++j) {
    const double e = tsa.average[j] - pattern(static_cast<double>(j) / 8192.0);
    err += e * e;
  }
  // Noise left: 1/√revs; interpolation of the impact's edges adds a little.
  EXPECT_LT(std::sqrt(err / 8192.0), 1.3 / std::sqrt(static_cast<double>(revs)));
  EXPECT_GT(tsa.residual_stats.kurtosis, 10.0);  // the impact alone is impulsive
  EXPECT_LT(tsa.average_stats.kurtosis, 2.0);    // the mesh tone dominates the average
}

TEST(SpeedTracking, FollowsAMeshLineDriftingTwoPercentWithoutATacho) {
  // A gearbox-like waveform on the reference shaft: mesh order 26 with two harmonics,
  // sidebands at ±1 and ±0.243 orders, a 1× line, Gaussian noise at 20 % of the RMS, the
  // speed drifting ±2 % over 20 s. The tracked angle must match θ(t) to 1 % of a
  // revolution, i.e. a mesh period to a quarter of its length.
  const Drift s;
  const double fs = 25600.0, duration = 12.0;
  const auto n = static_cast<std::size_t>(duration * fs);
  std::vector<double> x(n);
  std::mt19937_64 rng(4);
  std::normal_distribution<double> gauss(0.0, 0.35);
  for (std::size_t i = 0; i < n; ++i) {
    const double th = s.theta(i / fs);
    x[i] = std::cos(2.0 * kPiRad * 26.0 * th) + 0.5 * std::cos(2.0 * kPiRad * 52.0 * th + 0.3) +
           0.2 * std::cos(2.0 * kPiRad * 25.0 * th) + 0.2 * std::cos(2.0 * kPiRad * 27.0 * th) +
           0.1 * std::cos(2.0 * kPiRad * 26.243 * th) + 0.1 * std::cos(2.0 * kPiRad * 25.757 * th) +
           0.3 * std::cos(2.0 * kPiRad * th) + gauss(rng);
  }
  const std::vector<md::LineCandidate> candidates = {
      {26.0, 0.243}, {52.0, 0.243}, {5.1, 0.0555}, {0.96, 0.0097}};
  const md::TrackedSpeed t = md::track_speed(x.data(), n, fs, 14.0, candidates);
  ASSERT_TRUE(t.ok);
  EXPECT_NEAR(t.line_order, 26.0, 1e-9);
  // Angle error at every tracked pulse, the constant offset removed.
  const auto& p = t.map.pulses();
  double lo = 1e300, hi = 0.0;  // true speed range over the tracked span
  for (double tt = p.front(); tt <= p.back(); tt += 0.01) {
    lo = std::min(lo, s.hz(tt));
    hi = std::max(hi, s.hz(tt));
  }
  EXPECT_NEAR(t.min_hz, lo, 0.003 * s.f0);
  EXPECT_NEAR(t.max_hz, hi, 0.003 * s.f0);
  double offset = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k) offset += s.theta(p[k]) - static_cast<double>(k);
  offset /= static_cast<double>(p.size());
  double worst = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k)
    worst = std::max(worst, std::abs(s.theta(p[k]) - static_cast<double>(k) - offset));
  EXPECT_LT(worst, 0.01);
  // Without any line in the data there is nothing to follow.
  std::vector<double> noise(n);
  for (double& v : noise) v = gauss(rng);
  EXPECT_FALSE(md::track_speed(noise.data(), n, fs, 14.0, candidates).ok);
}

}  // namespace
