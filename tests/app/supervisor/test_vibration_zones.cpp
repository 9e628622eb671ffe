// ISO 10816-21 broadband evaluation (app/supervisor/vibration_zones.hpp) against hand
// values: the rms of a sine is A/√2, its velocity A/(2πf)/√2, a band-limiting filter
// passes what lies well inside its band and removes what lies well outside.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "supervisor/vibration_zones.hpp"

namespace {

using app::loop::PointSnapshot;
using app::loop::VibrationZone;
using app::supervisor::VibrationZones;
using app::supervisor::ZoneLimits;

constexpr double kFs = 25600.0;

ZoneLimits short_intervals() {
  ZoneLimits z;
  z.hf_interval_s = 2.0;
  z.lf_interval_s = 20.0;
  return z;
}

// Feeds `duration_s` of a sine (amplitude a, frequency f) in CMS-sized blocks.
void feed_sine(VibrationZones& v, double a, double f, double duration_s, double t0 = 0.0) {
  const auto n = static_cast<std::size_t>(duration_s * kFs);
  std::vector<float> block(28);
  for (std::size_t i = 0; i < n; i += block.size()) {
    const std::size_t m = std::min(block.size(), n - i);
    for (std::size_t k = 0; k < m; ++k)
      block[k] = static_cast<float>(
          a * std::sin(2.0 * std::numbers::pi * f * (t0 + static_cast<double>(i + k) / kFs)));
    v.add(block.data(), m);
  }
}

TEST(VibrationZones, ASineInsideTheBandsReadsItsRmsAndIntegratedVelocity) {
  // Arrange: 4 m/s² at 120 Hz, inside 10 Hz–2 kHz and 10 Hz–1 kHz.
  VibrationZones v(short_intervals(), kFs);
  // Act: settle one interval, read the second.
  feed_sine(v, 4.0, 120.0, 4.0);
  PointSnapshot p;
  v.fill(p);
  // Assert: a_rms = 4/√2; v_rms = a/(2πf)/√2 in mm/s; Butterworth at 120 Hz: |H| > 0.99.
  EXPECT_NEAR(p.accel_rms_10_2000_mps2, 4.0 / std::sqrt(2.0), 0.01 * 4.0 / std::sqrt(2.0));
  const double v_rms = 1e3 * 4.0 / (2.0 * std::numbers::pi * 120.0) / std::sqrt(2.0);
  EXPECT_NEAR(p.velocity_rms_10_1000_mmps, v_rms, 0.02 * v_rms);
  EXPECT_NEAR(p.rms_mps2, 4.0 / std::sqrt(2.0), 1e-3);
  EXPECT_NEAR(p.kurtosis, 1.5, 0.01);               // a sine's kurtosis
  EXPECT_TRUE(std::isnan(p.accel_rms_01_10_mps2));  // its 20 s interval is not complete yet
  // 3.75 mm/s: velocity in zone C (3.5 … 5.6), acceleration 2.8 m/s² below 7.5: worst is C.
  EXPECT_EQ(v.zone(), VibrationZone::kC);
}

TEST(VibrationZones, EachBandRejectsWhatLiesOutsideIt) {
  // 4 kHz: above both upper edges (2nd order: |H(4 kHz)| of the 2 kHz low-pass ≈ 0.24).
  VibrationZones hi(short_intervals(), kFs);
  feed_sine(hi, 10.0, 4000.0, 4.0);
  PointSnapshot p;
  hi.fill(p);
  EXPECT_LT(p.accel_rms_10_2000_mps2, 0.3 * 10.0 / std::sqrt(2.0));
  // 10 m/s² at 4 kHz is 0.28 mm/s; the 1 kHz low-pass passes 1/√(1 + 4⁴) of it: 0.017 mm/s.
  EXPECT_LT(p.velocity_rms_10_1000_mmps, 0.03);
  // 1 Hz: below the 10 Hz high-passes, inside 0.1–10 Hz.
  VibrationZones lo(short_intervals(), kFs);
  feed_sine(lo, 0.4, 1.0, 42.0);
  lo.fill(p);
  EXPECT_LT(p.accel_rms_10_2000_mps2, 0.02 * 0.4);
  EXPECT_NEAR(p.accel_rms_01_10_mps2, 0.4 / std::sqrt(2.0), 0.03 * 0.4 / std::sqrt(2.0));
  // 0.28 m/s² in 0.1–10 Hz: zone A/B (< 0.3); 0.8 m/s² would be D.
  EXPECT_EQ(lo.zone(), VibrationZone::kAB);
  VibrationZones lo2(short_intervals(), kFs);
  feed_sine(lo2, 0.8, 1.0, 42.0);
  EXPECT_EQ(lo2.zone(), VibrationZone::kD);
}

TEST(VibrationZones, AnIntervalWithTooFewSamplesIsNotJudged) {
  // Arrange: a loud sine, then an interval with a 20 % gap.
  VibrationZones v(short_intervals(), kFs);
  feed_sine(v, 30.0, 120.0, 2.0);
  ASSERT_EQ(v.zone(), VibrationZone::kD);
  // Act: 1.6 s of samples and 0.4 s lost (coverage 0.8 < 0.9).
  std::vector<float> x(static_cast<std::size_t>(1.6 * kFs), 0.1f);
  v.add(x.data(), x.size(), static_cast<std::size_t>(0.4 * kFs));
  // Assert
  PointSnapshot p;
  v.fill(p);
  EXPECT_TRUE(std::isnan(p.accel_rms_10_2000_mps2));
  EXPECT_EQ(v.zone(), VibrationZone::kUnknown);
}

TEST(VibrationZones, ZoneBoundariesAreTheConfiguredOnes) {
  EXPECT_EQ(app::supervisor::zone_of(7.49, 7.5, 12.0), VibrationZone::kAB);
  EXPECT_EQ(app::supervisor::zone_of(7.5, 7.5, 12.0), VibrationZone::kC);
  EXPECT_EQ(app::supervisor::zone_of(12.0, 7.5, 12.0), VibrationZone::kD);
  EXPECT_EQ(app::supervisor::zone_of(-1.0, 7.5, 12.0), VibrationZone::kUnknown);
  EXPECT_EQ(app::supervisor::zone_of(std::nan(""), 7.5, 12.0), VibrationZone::kUnknown);
}

}  // namespace
