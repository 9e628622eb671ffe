// ISO 281 bearing life, remaining useful life, and the load spectrum of history mode.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "model/fatigue/drivetrain_channels.hpp"
#include "model/fatigue/load_spectrum.hpp"
#include "model/fatigue/rul.hpp"

namespace {
using namespace model::fatigue;

TEST(BearingLife, Iso281BasicRatingLifeUsesExponentThreeForBallsAndTenThirdsForRollers) {
  // C = 100 kN, P = 10 kN: ball L10 = 10³ = 1000 Mrev; roller 10^(10/3) = 2154.43 Mrev.
  EXPECT_NEAR(l10_million_revs(100e3, 10e3, model::BearingType::kBall), 1000.0, 1e-9);
  EXPECT_NEAR(l10_million_revs(100e3, 10e3, model::BearingType::kRoller), 2154.4347, 1e-4);
}

TEST(BearingLife, EquivalentLoadOfAnAngularRollerBearingFollowsIso281XAndY) {
  // α = 15°: e = 1.5·tan15° = 0.401924. F_r = 10 kN, F_a = 5 kN: F_a/F_r = 0.5 > e, single row:
  // P = 0.4·10 + 0.4·cot15°·5 = 4 + 0.4·3.732051·5 = 11.464102 kN. F_a = 3 kN ≤ e·F_r: P = F_r.
  model::Bearing b;
  b.type = model::BearingType::kRoller;
  b.contact_angle_rad = 15.0 * std::numbers::pi / 180.0;
  b.rows = 1;
  EXPECT_NEAR(equivalent_load_n(b, 10e3, 5e3), 11464.102, 1e-3);
  EXPECT_NEAR(equivalent_load_n(b, 10e3, 3e3), 10e3, 1e-9);
}

TEST(BearingLife, AccumulatedBearingDamageIsRevolutionsOverL10) {
  // b5 of paper-2mw on the hss: 1 h at rotor 12 rpm → hss revs = 720·103.0246;
  // D = revs/(1e6·(C/P)^(10/3)) (the basic rating life: a_ISO switched off). C from the
  // geometry (ISO 281:2007) with the reference's catalogue figure removed and L_we = D_we =
  // 28 mm: γ = 28/150 = 0.18667, f_c = 88.8, C = 1.1·88.8·28^(7/9)·16^(3/4)·28^(29/27)
  // = 1.1·88.8·13.35265·8·35.83892 = 373 953.8 N.
  model::Drivetrain d = model::paper_2mw();
  for (model::Bearing& b : d.bearings) {
    if (b.id != "b5") continue;
    b.dynamic_rating_n = 0.0;
    b.roller_effective_length_m = b.element_diameter_m;
  }
  ChannelOptions options;
  options.lubrication.enabled = false;
  const ChannelSet cs(d, options);
  DamageAccumulator acc(cs, {});
  const LoadSample l = cs.quasi_static_loads(9e5);
  for (int i = 0; i < 3600; ++i) acc.step(l, 12.0, 1000);
  for (std::size_t c = 0; c < cs.channel_count(); ++c) {
    if (cs.channel(c).component != "b5") continue;
    const double p = cs.stress(c, 0, l);
    const double revs = 720.0 * (1 + 99.0 / 21) * (92.0 / 21) * (107.0 / 26);
    EXPECT_NEAR(acc.damage(c),
                revs / (1e6 * l10_million_revs(373953.8, p, model::BearingType::kRoller)),
                1e-6 * acc.damage(c));
  }
}

TEST(RemainingLife, ConstantDamageRateGivesTheTimeWhenDamageReachesOne) {
  // 100 days of ΔD = 1e-4 per day, D = 0.25: rate = 1e-4/86400 s; RUL = 0.75/rate = 7500 days.
  DamageRateHistory h(86400.0, 30);
  for (int i = 0; i < 100; ++i) h.add_interval(1e-4);
  const RulEstimate e = h.estimate(0.25);
  EXPECT_NEAR(e.rul_s / 86400.0, 7500.0, 1e-6);
  EXPECT_NEAR(e.rul_short_term_s / 86400.0, 7500.0, 1e-6);
  EXPECT_NEAR(e.rul_low_s, e.rul_high_s, 1e-3);
}

TEST(RemainingLife, BandWidensWithVaryingRateAndShortTermFollowsRecentIntervals) {
  DamageRateHistory h(86400.0, 10);
  for (int i = 0; i < 200; ++i) h.add_interval(i % 20 < 10 ? 1e-5 : 3e-5);
  for (int i = 0; i < 10; ++i) h.add_interval(1e-4);  // a stormy recent fortnight
  const RulEstimate e = h.estimate(0.5);
  EXPECT_LT(e.rul_low_s, e.rul_s);
  EXPECT_LT(e.rul_s, e.rul_high_s);
  EXPECT_NEAR(e.short_term_rate_per_s, 1e-4 / 86400.0, 1e-20);
  EXPECT_LT(e.rul_short_term_s, e.rul_s);
}

TEST(RemainingLife, IsZeroOnceDamageReachesOneAndInfiniteWithoutDamageRate) {
  EXPECT_DOUBLE_EQ(time_to_failure_s(1.2, 1e-9), 0.0);
  EXPECT_TRUE(std::isinf(time_to_failure_s(0.3, 0.0)));
}

TEST(LoadSpectrum, InterpolationReproducesTheAccumulatorOnAndBetweenGridPoints) {
  // Arrange: quasi-static spectrum on 61 torque points up to 1.5·rated.
  const model::Drivetrain d = model::paper_2mw();
  const ChannelSet cs(d, ChannelOptions{});
  SpectrumGrid g;
  g.torque_max_nm = 1.5 * 1.23e6;
  g.speed_max_rpm = 16.0;
  std::string error;
  const LoadSpectrum s =
      build_load_spectrum(cs, g, SpectrumSource::kQuasiStatic, quasi_static_simulator(cs), &error);
  ASSERT_EQ(s.channel_count, cs.channel_count()) << error;
  std::vector<double> interp(cs.channel_count());
  for (double torque : {g.torque_at(40), 1.0e6, 1.17e6}) {
    // Act
    s.damage_per_rev_at(torque, 14.0, interp.data());
    DamageAccumulator direct(cs, {});
    direct.step(cs.quasi_static_loads(torque), 14.0, 60000);  // 60 s at 1 ms ticks: 14 revs
    // Assert: at a grid point exact; between (2.5 % torque steps) within 1 % for the sun,
    // whose damage ∝ T^16.5 is the most curved.
    for (std::size_t c = 0; c < cs.channel_count(); ++c) {
      const double want = direct.damage(c) / direct.rotor_revolutions();
      EXPECT_NEAR(interp[c], want, 1e-2 * want) << cs.channel(c).component << " at " << torque;
    }
  }
}

TEST(LoadSpectrum, ReportsTheGridPointWhereTheSimulatorFailed) {
  const model::Drivetrain d = model::paper_2mw();
  const ChannelSet cs(d, ChannelOptions{});
  SpectrumGrid g;
  g.torque_max_nm = 1e6;
  g.speed_max_rpm = 15.0;
  std::string error;
  const LoadSpectrum s = build_load_spectrum(
      cs, g, SpectrumSource::kDynamics, [](double t, double, LoadSeries&) { return t < 5e5; },
      &error);
  EXPECT_EQ(s.channel_count, 0u);
  EXPECT_NE(error.find("torque"), std::string::npos);
}

}  // namespace
