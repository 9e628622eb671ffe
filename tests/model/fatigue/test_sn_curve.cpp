// Dual-slope S-N curve (ISO 6336-6, Haibach) and the ISO 6336-2 life-factor line.
#include <gtest/gtest.h>

#include <cmath>

#include "model/fatigue/sn_curve.hpp"

namespace {
using model::fatigue::KneeBranch;
using model::fatigue::SnCurve;

SnCurve paper_sun(KneeBranch branch = KneeBranch::kHaibach) {
  SnCurve c;
  c.m = 17.035;
  c.c = 3090.3;
  c.knee_cycles = 5e7;
  c.branch = branch;
  return c;
}

TEST(SnCurve, PaperSunCurveHasItsKneeStressAtFiveTimesTenToTheSeven) {
  // σ_k = C·N0^(−1/m) = 3090.3·(5e7)^(−1/17.035) = 1091.57 MPa (hand: ln 5e7 = 17.72753,
  // /17.035 = 1.040654, e^−1.040654 = 0.353222).
  const SnCurve c = paper_sun();
  EXPECT_NEAR(c.knee_stress(), 1091.57, 0.01);
  EXPECT_NEAR(c.cycles_to_failure(c.knee_stress()), 5e7, 5e7 * 1e-12);
}

TEST(SnCurve, IsContinuousAtTheKneeWithSlopeMinusOneOverMBelowAndOneOver2mMinus1Above) {
  const SnCurve c = paper_sun();
  const double sk = c.knee_stress();
  EXPECT_NEAR(c.cycles_to_failure(sk * (1 + 1e-9)) / c.cycles_to_failure(sk * (1 - 1e-9)), 1.0,
              1e-6);
  // Below the knee (N < N0): log σ/log N slope −1/m.
  const double s1 = 1.5 * sk, s2 = 1.4 * sk;
  const double below =
      std::log(s2 / s1) / std::log(c.cycles_to_failure(s2) / c.cycles_to_failure(s1));
  EXPECT_NEAR(below, -1.0 / 17.035, 1e-12);
  // Above the knee: −1/(2m − 1) = −1/33.07.
  const double s3 = 0.9 * sk, s4 = 0.8 * sk;
  const double above =
      std::log(s4 / s3) / std::log(c.cycles_to_failure(s4) / c.cycles_to_failure(s3));
  EXPECT_NEAR(above, -1.0 / 33.07, 1e-12);
}

TEST(SnCurve, IsoLifeFactorLineFallsToEightyFivePercentOfTheKneeStressAtTenToTheTen) {
  const SnCurve c = paper_sun(KneeBranch::kIsoLifeLine);
  EXPECT_NEAR(c.cycles_to_failure(0.85 * c.knee_stress()), 1e10, 1e10 * 1e-10);
  EXPECT_NEAR(c.cycles_to_failure(c.knee_stress() * (1 - 1e-12)), 5e7, 5e7 * 1e-8);
}

TEST(SnCurve, BearingCurveWithoutKneeIsTheIso281Life) {
  // L10 = 1e6·(C/P)^(10/3); C/P = 10 → 2.1544347e9 revolutions.
  SnCurve c;
  c.m = 10.0 / 3.0;
  c.c = 100e3;
  c.n_ref = 1e6;
  c.branch = KneeBranch::kNone;
  EXPECT_NEAR(c.cycles_to_failure(10e3), 2.1544347e9, 1e2);
}

TEST(SnCurve, ZeroOrNegativeStressCausesNoDamage) {
  const SnCurve c = paper_sun();
  EXPECT_DOUBLE_EQ(c.damage_per_cycle(0.0), 0.0);
  EXPECT_DOUBLE_EQ(c.damage_per_cycle(-5.0), 0.0);
  EXPECT_TRUE(std::isinf(c.cycles_to_failure(0.0)));
}

}  // namespace
