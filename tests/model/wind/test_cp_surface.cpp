// Cp(λ, β) surface against hand calculations of Heier's formula and the paper's
// published maximum (VBDM-DT: Cp_max = 0.48 at λ_opt = 8.03, β = 0).
#include <gtest/gtest.h>

#include <numbers>

#include "model/drivetrain/description.hpp"
#include "model/wind/cp_surface.hpp"

namespace {

model::CpSurface textbook_surface() {
  model::CpSurface s;
  s.c = {0.5176, 116.0, 0.4, 5.0, 21.0, 0.0068};
  s.lambda_i_beta = 0.08;
  s.lambda_i_cubic = 0.035;
  s.lambda_scale = 1.0;
  return s;
}

constexpr double kDeg = std::numbers::pi / 180.0;

TEST(CpSurface, MatchesAHandCalculationOfHeiersFormulaWithPitch) {
  // Arrange: λ = 6, β = 5°:
  //   1/λi = 1/(6 + 0.08·5) − 0.035/(125 + 1) = 0.156250 − 0.000278 = 0.155972
  //   Cp   = 0.5176·(116·0.155972 − 0.4·5 − 5)·exp(−21·0.155972) + 0.0068·6
  //        = 0.5176·11.0928·0.037800 + 0.0408 = 0.25784
  const model::CpSurface s = textbook_surface();
  // Act
  const double cp = model::wind::power_coefficient(s, 6.0, 5.0 * kDeg);
  // Assert
  EXPECT_NEAR(cp, 0.25784, 5e-5);
}

TEST(CpSurface, LambdaScaleEvaluatesTheSurfaceAtTheScaledTipSpeedRatio) {
  model::CpSurface scaled = textbook_surface();
  scaled.lambda_scale = 1.5;
  EXPECT_DOUBLE_EQ(model::wind::power_coefficient(scaled, 4.0, 0.0),
                   model::wind::power_coefficient(textbook_surface(), 6.0, 0.0));
}

TEST(CpSurface, IsNeverNegativeAndZeroForNonPositiveTipSpeedRatio) {
  const model::CpSurface s = textbook_surface();
  EXPECT_EQ(model::wind::power_coefficient(s, 0.0, 0.0), 0.0);
  EXPECT_EQ(model::wind::power_coefficient(s, -3.0, 0.0), 0.0);
  // Very low λ: c2/λi − c4 < 0 would give a negative Cp; clamped.
  EXPECT_GE(model::wind::power_coefficient(s, 1.0, 0.0), 0.0);
  EXPECT_GE(model::wind::power_coefficient(s, 2.0, 60.0 * kDeg), 0.0);
}

TEST(CpSurface, TextbookCoefficientsPeakAtCpPointFourEightNearLambdaEightPointOne) {
  // Slootweg et al. 2003 state Cp_max = 0.48 at λ ≈ 8.1 for these coefficients.
  const model::wind::CpPeak peak = model::wind::find_cp_peak(textbook_surface());
  EXPECT_NEAR(peak.cp_max, 0.48, 0.001);
  EXPECT_NEAR(peak.lambda_opt, 8.1, 0.01);
}

TEST(CpSurface, PaperTurbineSurfacePeaksAtThePapersCpMaxAndLambdaOpt) {
  // Arrange: the built-in paper-2mw surface.
  const model::Drivetrain d = model::paper_2mw();
  // Act: search the surface (not the description's cp_max / lambda_opt fields).
  const model::wind::CpPeak peak = model::wind::find_cp_peak(d.turbine.cp);
  // Assert: paper, Cp_max = 0.48 at λ_opt = 8.03.
  EXPECT_NEAR(peak.cp_max, 0.48, 0.005);
  EXPECT_NEAR(peak.lambda_opt, 8.03, 0.1);
  // And it is a maximum: both neighbours half a unit away are lower.
  EXPECT_LT(model::wind::power_coefficient(d.turbine.cp, peak.lambda_opt - 0.5, 0.0), peak.cp_max);
  EXPECT_LT(model::wind::power_coefficient(d.turbine.cp, peak.lambda_opt + 0.5, 0.0), peak.cp_max);
}

TEST(CpSurface, PitchingTheBladesReducesCpMonotonicallyAtTheOptimumTipSpeedRatio) {
  const model::CpSurface s = textbook_surface();
  double previous = model::wind::power_coefficient(s, 8.1, 0.0);
  for (double beta_deg = 1.0; beta_deg <= 20.0; beta_deg += 1.0) {
    const double cp = model::wind::power_coefficient(s, 8.1, beta_deg * kDeg);
    EXPECT_LT(cp, previous) << "beta = " << beta_deg << " deg";
    previous = cp;
  }
}

}  // namespace
