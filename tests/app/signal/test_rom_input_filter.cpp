// The ROM's input filter (app/signal/rom_input_filter.hpp): its step response against the
// closed form of four equal first-order sections, its gain at the first torsional mode and
// in the SCADA's band against |H(f)|, exact levels and integrals; and, with the ROM and the
// damage accumulator, that a stepped SCADA torque is counted as its levels, not as the
// ringing a held-then-stepped input causes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

#include "fatigue/dynamics_spectrum.hpp"
#include "model/drivetrain/description.hpp"
#include "model/dynamics/rom.hpp"
#include "model/fatigue/damage_accumulator.hpp"
#include "model/fatigue/drivetrain_channels.hpp"
#include "signal/rom_input_filter.hpp"

namespace {

using app::signal::RomInputFilter;
using app::signal::RomInputFilterSettings;
using model::dynamics::RomInputs;
constexpr double kPi = std::numbers::pi;

// Gamma(4) distribution function: the step response of four equal sections.
double gamma4_cdf(double x) {
  return 1.0 - std::exp(-x) * (1.0 + x + x * x / 2.0 + x * x * x / 6.0);
}

TEST(RomInputFilter, StepResponseIsTheClosedFormOfFourEqualSections) {
  // Arrange
  RomInputFilter f({0.6, 1e-3});
  f.reset({10.0, 0.0});
  const double tau = f.time_constant_s();
  EXPECT_NEAR(tau, 1.0 / (2.0 * kPi * 0.6), 1e-15);
  // Act / Assert: torque 0 → 1e6 N·m, speed 10 → 12 rpm at t = 0.
  double worst = 0.0;
  for (int k = 1; k <= 5000; ++k) {
    f.update({12.0, 1.0e6});
    const double x = k * 1e-3 / tau;
    worst = std::max(worst, std::abs(f.output().input_torque_nm - 1.0e6 * gamma4_cdf(x)));
    worst = std::max(worst,
                     1e6 / 2.0 * std::abs(f.output().rotor_speed_rpm - 10.0 - 2.0 * gamma4_cdf(x)));
  }
  EXPECT_LT(worst, 1e-6);  // [N·m] of 1e6
  // and the new level is reached, without overshoot (40τ: Gamma(4) leaves 1e-13)
  double peak = 0.0;
  for (int k = 0; k < 6000; ++k) {
    f.update({12.0, 1.0e6});
    peak = std::max(peak, f.output().input_torque_nm);
  }
  EXPECT_LE(peak, 1.0e6);
  EXPECT_NEAR(f.output().input_torque_nm, 1.0e6, 1e-6);
}

TEST(RomInputFilter, StepsWithinACycleRunStraightToTheCyclesOutput) {
  RomInputFilter f({0.6, 1e-3});
  f.reset({10.0, 0.0});
  f.update({10.0, 1.0e6});
  const double y = f.output().input_torque_nm;
  ASSERT_GT(y, 0.0);
  for (int i = 0; i < 8; ++i) EXPECT_NEAR(f.at_step(i, 8).input_torque_nm, y * (i + 1) / 8.0, 1e-9);
  EXPECT_EQ(f.at_step(7, 8).input_torque_nm, y);
}

TEST(RomInputFilter, TheCornerLeavesTheRequestedResidualAtTheFirstModeAndPassesTheScadaBand) {
  // Arrange: f₁ = 1.9 Hz; corner for 1 %.
  const double f1 = 1.9;
  const double fc = RomInputFilter::corner_for_first_mode(f1);
  EXPECT_NEAR(std::pow(1.0 + (f1 / fc) * (f1 / fc), -2.0), 0.01, 1e-12);
  // Act: sines through the discrete filter (1 ms cycles), amplitude after the transient.
  const auto gain = [&](double f_hz) {
    RomInputFilter f({fc, 1e-3});
    f.reset({0.0, 0.0});
    double peak = 0.0;
    const int n = static_cast<int>(std::ceil((20.0 + 5.0 / f_hz) / 1e-3));
    for (int k = 0; k < n; ++k) {
      const double t = k * 1e-3;
      f.update({0.0, std::sin(2.0 * kPi * f_hz * t)});
      if (t > 20.0) peak = std::max(peak, std::abs(f.output().input_torque_nm));
    }
    return peak;
  };
  // Assert: |H(f)| = (1 + (f/f_c)²)^(−2) (the cycle's hold adds a delay, not a gain error,
  // at these frequencies: sinc(f T) ≥ 1 − 1e-5).
  for (const double f_hz : {0.02, 0.1, 0.3, f1}) {
    const double h = std::pow(1.0 + (f_hz / fc) * (f_hz / fc), -2.0);
    EXPECT_NEAR(gain(f_hz), h, 2e-3 * h + 1e-5) << f_hz << " Hz";
  }
}

TEST(RomInputFilter, KeepsTheIntegralOfItsInputAndDelaysItByFourTimeConstants) {
  RomInputFilter f({0.6, 1e-3});
  f.reset({10.0, 5.0e5});
  double in_sum = 0.0, out_sum = 0.0;
  const int n = 60000;  // 60 s: 40τ after the step
  for (int k = 0; k < n; ++k) {
    const double u = k < 1000 ? 5.0e5 : 8.0e5;
    f.update({10.0, u});
    in_sum += u * 1e-3;
    out_sum += f.output().input_torque_nm * 1e-3;
  }
  // The output's integral lags by the step × the filter's mean delay 4τ (the Gamma(4, τ) mean),
  // less the half cycle by which a held input leads its samples.
  const double tau = f.time_constant_s();
  EXPECT_NEAR(in_sum - out_sum, 3.0e5 * (4.0 * tau), 3.0e5 * 1e-3);
  EXPECT_NEAR(f.output().input_torque_nm, 8.0e5, 1e-6);
}

}  // namespace
