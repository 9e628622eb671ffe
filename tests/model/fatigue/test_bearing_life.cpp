// ISO 281:2007 life modification factor a_ISO and its inputs (model/fatigue/bearing_life.hpp):
// hand calculations written out below, the standard's own properties (a_ISO = 0.1 without a
// contamination margin, the κ branches joining, the cap at 50), ISO 76 C0 and the C_u
// approximation on the reference's b1, and the damage of a bearing channel divided by a_ISO.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "model/fatigue/bearing_life.hpp"
#include "model/fatigue/bearing_rating.hpp"
#include "model/fatigue/damage_accumulator.hpp"
#include "model/fatigue/drivetrain_channels.hpp"

namespace {
using model::Bearing;
using model::BearingType;
using namespace model::fatigue;

TEST(BearingLife, OilViscosityFollowsAstmD341ThroughBothReferencePoints) {
  // ISO VG 320 PAO, ν40 = 320, ν100 = 35 mm²/s. By hand: Z = log10 log10(ν + 0.7):
  // Z40 = 0.398998, Z100 = 0.191079; B = (Z40 − Z100)/(log 373.15 − log 313.15) = 2.731075;
  // A = Z40 + B·log 313.15 = 7.215085; at 70 °C: Z = A − B·log 343.15, ν = 10^10^Z − 0.7 = 88.844.
  EXPECT_NEAR(kinematic_viscosity_mm2_s(320.0, 35.0, 40.0), 320.0, 1e-9);
  EXPECT_NEAR(kinematic_viscosity_mm2_s(320.0, 35.0, 100.0), 35.0, 1e-9);
  EXPECT_NEAR(kinematic_viscosity_mm2_s(320.0, 35.0, 70.0), 88.844, 1e-3);
  // Colder oil is thicker.
  EXPECT_GT(kinematic_viscosity_mm2_s(320.0, 35.0, 50.0),
            kinematic_viscosity_mm2_s(320.0, 35.0, 60.0));
}

TEST(BearingLife, RatedViscosityOfIso281BelowAndAbove1000Rpm) {
  // ν1 = 45000·n^−0.83·D_pw^−0.5: n = 85 rpm, D_pw = 400 mm: 45000·0.025034/20 = 56.333.
  EXPECT_NEAR(rated_viscosity_mm2_s(85.0, 400.0), 56.333, 1e-3);
  // ν1 = 4500·n^−0.5·D_pw^−0.5: n = 1500 rpm, D_pw = 150 mm: 4500/(38.730·12.247) = 9.4868.
  EXPECT_NEAR(rated_viscosity_mm2_s(1500.0, 150.0), 9.4868, 1e-4);
  EXPECT_EQ(rated_viscosity_mm2_s(0.0, 150.0), 0.0);
}

TEST(BearingLife, LifeModificationFactorOfRollerBearingsByHand) {
  // κ = 1, e_C·C_u/P = 0.1: 1.5859 − 1.2348/1 = 0.3511; 0.1^0.4 = 0.398107; 1 − 0.3511·0.398107
  // = 0.860225; 0.860225^−9.185 = e^(9.185·0.150561) = 3.98649; a_ISO = 0.398649.
  EXPECT_NEAR(life_modification_factor(BearingType::kRoller, 1.0, 0.1), 0.398649, 1e-6);
  // κ = 2, x = 0.2 (1 ≤ κ ≤ 4 branch): 1.2348/2^0.071739 = 1.1749; (1.5859 − 1.1749)·0.2^0.4
  // = 0.4110·0.52531 = 0.21591; 0.78409^−9.185 = 9.3368; a_ISO = 0.93368.
  EXPECT_NEAR(life_modification_factor(BearingType::kRoller, 2.0, 0.2), 0.93368, 1e-4);
}

TEST(BearingLife, LifeModificationFactorHasTheStandardsProperties) {
  for (BearingType type : {BearingType::kRoller, BearingType::kBall}) {
    // No contamination margin (e_C·C_u/P = 0): 0.1 whatever the lubrication.
    for (double kappa : {0.1, 0.3, 0.7, 1.0, 2.5, 4.0}) {
      EXPECT_NEAR(life_modification_factor(type, kappa, 0.0), 0.1, 1e-12);
    }
    // The κ branches join, to the standard's constants' printed digits (their inner terms agree
    // to ~1e-5 at κ = 0.4, which the exponent −9.3 turns into up to ~7e-4 of a_ISO).
    for (double x : {0.05, 0.2, 0.5}) {
      EXPECT_NEAR(
          life_modification_factor(type, 0.4 - 1e-12, x) / life_modification_factor(type, 0.4, x),
          1.0, 1e-3);
      EXPECT_NEAR(life_modification_factor(type, 1.0 - 1e-12, x),
                  life_modification_factor(type, 1.0, x), 1e-9);
    }
    // Capped at 50; κ above 4 counts as 4, below 0.1 as 0.1.
    EXPECT_DOUBLE_EQ(life_modification_factor(type, 4.0, 50.0), 50.0);
    EXPECT_DOUBLE_EQ(life_modification_factor(type, 10.0, 0.3),
                     life_modification_factor(type, 4.0, 0.3));
    EXPECT_DOUBLE_EQ(life_modification_factor(type, 0.01, 0.3),
                     life_modification_factor(type, 0.1, 0.3));
    // More film and more margin both lengthen life.
    double previous = 0.0;
    for (double kappa = 0.1; kappa <= 4.0; kappa += 0.05) {
      const double a = life_modification_factor(type, kappa, 0.3);
      EXPECT_GE(a, previous - 1e-12) << kappa;
      previous = a;
    }
    EXPECT_LT(life_modification_factor(type, 1.0, 0.1), life_modification_factor(type, 1.0, 0.3));
  }
}

Bearing reference_b1() {
  // shared/reference/drivetrain-2mw.md: b1, cylindrical roller, 1 row, Z = 22, D_we = 40 mm,
  // D_pw = 400 mm, L_we = 60 mm, catalogue C = 1700 kN.
  Bearing b;
  b.id = "b1";
  b.elements = 22;
  b.rows = 1;
  b.element_diameter_m = 0.040;
  b.pitch_diameter_m = 0.400;
  b.contact_angle_rad = 0.0;
  b.type = BearingType::kRoller;
  b.roller_effective_length_m = 0.060;
  b.dynamic_rating_n = 1.7e6;
  return b;
}

TEST(BearingLife, StaticRatingAndFatigueLoadLimitOfTheReferenceB1) {
  const Bearing b = reference_b1();
  // ISO 76: C0 = 44·(1 − 40/400)·1·22·60·40 = 44·0.9·52800 = 2 090 880 N.
  EXPECT_NEAR(iso76_static_rating_n(b), 2090880.0, 1e-6);
  // ISO 281's approximation, D_pw > 100 mm: C_u = C0/8.2·(100/400)^0.3 = 254985.4·0.659754 = 168
  // 227.6.
  EXPECT_NEAR(effective_fatigue_load_limit_n(b), 168227.6, 0.1);
  // Given figures win; a ball bearing needs them.
  Bearing given = b;
  given.static_rating_n = 3.0e6;
  EXPECT_NEAR(effective_fatigue_load_limit_n(given), 3.0e6 / 8.2 * std::pow(0.25, 0.3), 1e-6);
  given.fatigue_load_limit_n = 2.0e5;
  EXPECT_DOUBLE_EQ(effective_fatigue_load_limit_n(given), 2.0e5);
  Bearing ball = b;
  ball.type = BearingType::kBall;
  EXPECT_EQ(iso76_static_rating_n(ball), 0.0);
  EXPECT_EQ(effective_fatigue_load_limit_n(ball), 0.0);
}

TEST(BearingLife, Paper2mwUsesTheCatalogueRatingsAndTheGeometricOnesRemainAsACheck) {
  const ChannelSet cs(model::paper_2mw(), ChannelOptions{});
  ASSERT_TRUE(cs.valid()) << cs.error();
  int checked = 0;
  for (std::size_t s = 0; s < cs.bearing_count(); ++s) {
    const std::string& id = cs.bearing_id(s);
    if (id == "b1") {
      EXPECT_DOUBLE_EQ(cs.bearing(s).dynamic_rating_n, 1.7e6);
      // ISO 281 from the geometry, L_we = 60 mm: 1.1·84.2·60^(7/9)·22^(3/4)·40^(29/27).
      EXPECT_NEAR(iso281_dynamic_rating(cs.bearing(s)).c_n, 1194701.5, 1.0);
      EXPECT_NEAR(cs.bearing_life(s).c0_n, 2090880.0, 1e-6);
      EXPECT_TRUE(cs.bearing_life(s).applied);
      ++checked;
    }
    if (id == "b4") {  // tapered roller, paired: the set's rating, two rows
      EXPECT_DOUBLE_EQ(cs.bearing(s).dynamic_rating_n, 1.35e6);
      EXPECT_EQ(cs.bearing(s).rows, 2);
      ++checked;
    }
    if (id.rfind("pb", 0) == 0) {
      EXPECT_DOUBLE_EQ(cs.bearing(s).dynamic_rating_n, 2.9e6);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 5);  // b1, b4 and three planet bearings
}

TEST(BearingLife, BearingDamageIsTheBasicDamageOverAIso) {
  // Arrange: paper-2mw at constant rated torque and speed for one hour, with and without a_ISO.
  const model::Drivetrain d = model::paper_2mw();
  ChannelOptions with;
  ChannelOptions without;
  without.lubrication.enabled = false;
  const ChannelSet cs(d, with), basic(d, without);
  ASSERT_TRUE(cs.valid() && basic.valid());
  const LoadSample loads = cs.quasi_static_loads(d.turbine.rated_torque_nm);
  const double rpm = d.turbine.rated_rotor_speed_rpm;
  AccumulatorConfig cfg;
  cfg.tick_s = 1.0;
  DamageAccumulator a(cs, cfg), b(basic, cfg);
  for (int i = 0; i < 3600; ++i) {
    a.step(loads, rpm, 1);
    b.step(loads, rpm, 1);
  }
  // Assert: every bearing channel's damage is the basic one over the slot's a_ISO at that load
  // and speed; gear channels are untouched.
  int bearings = 0;
  for (std::size_t c = 0; c < cs.channel_count(); ++c) {
    const Channel& ch = cs.channel(c);
    if (ch.mode != FailureMode::kBearing) {
      EXPECT_DOUBLE_EQ(a.damage(c), b.damage(c));
      continue;
    }
    const std::size_t slot = ch.sources[0].slot;
    const double p = equivalent_load_n(cs.bearing(slot), loads.bearing_radial_n[slot],
                                       loads.bearing_axial_n[slot]);
    const double a_iso = cs.life_modification(slot, p, rpm);
    EXPECT_GT(a_iso, 0.1);
    EXPECT_NEAR(a.damage(c) * a_iso / b.damage(c), 1.0, 1e-9) << ch.component;
    ++bearings;
  }
  EXPECT_EQ(bearings, 9);  // b1..b6 and three planet bearings
  // b1 at rated: the sun shaft turns 84.57 rpm, ν1 = 45000·84.57^−0.83/√400 = 56.571 mm²/s,
  // κ = 88.844/56.571 = 1.5705.
  for (std::size_t s = 0; s < cs.bearing_count(); ++s) {
    if (cs.bearing_id(s) != "b1") continue;
    const BearingLifeTerms& t = cs.bearing_life(s);
    EXPECT_NEAR(t.viscosity_mm2_s / rated_viscosity_mm2_s(rpm * t.rev_per_rotor_rev, 400.0), 1.5705,
                5e-4);
  }
}

}  // namespace
