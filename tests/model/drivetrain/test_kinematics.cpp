// Kinematics of paper-2mw against the table "Kinematics at the two reference
// operating points" of shared/reference/drivetrain-2mw.md (computed there by hand
// from the tooth counts and bearing geometry).
#include <gtest/gtest.h>

#include "model/drivetrain/description.hpp"
#include "model/drivetrain/kinematics.hpp"

namespace {

struct Row {
  double rotor_rpm;
  double lss, sun_shaft, ims, hss, planetary_mesh, intermediate_mesh, high_speed_mesh, planet_pass;
  double b5_bpfo, b5_bpfi, b6_bpfo, b6_bpfi, b3_bpfo, b3_bpfi;
};

// Values as printed in the reference (4–5 significant figures).
constexpr Row kPaperPoint{8.33,   0.1388, 0.7933,  3.4756, 14.3032, 13.745, 72.987, 371.884,
                          0.4165, 93.066, 135.785, 81.989, 118.256, 26.928, 35.632};
constexpr Row kRated{14.8,   0.2467,  1.4095,  6.1751,  25.4127, 24.420, 129.676, 660.731,
                     0.7400, 165.352, 241.252, 145.671, 210.107, 47.843, 63.308};

void expect_row(const Row& r) {
  const model::Drivetrain d = model::paper_2mw();
  const model::Kinematics k(d);
  // The table is rounded to its last printed digit: allow half of that plus 0.01 %.
  auto near = [](double got, double want, double step) {
    EXPECT_NEAR(got, want, 0.5 * step + 1e-4 * want) << "want " << want;
  };
  near(*k.shaft_hz("lss", r.rotor_rpm), r.lss, 1e-4);
  near(*k.shaft_hz("sun_shaft", r.rotor_rpm), r.sun_shaft, 1e-4);
  near(*k.shaft_hz("ims", r.rotor_rpm), r.ims, 1e-4);
  near(*k.shaft_hz("hss", r.rotor_rpm), r.hss, 1e-4);
  near(k.mesh_hz(0, r.rotor_rpm), r.planetary_mesh, 1e-3);
  near(k.mesh_hz(1, r.rotor_rpm), r.intermediate_mesh, 1e-3);
  near(k.mesh_hz(2, r.rotor_rpm), r.high_speed_mesh, 1e-3);
  near(k.planet_pass_hz(0, r.rotor_rpm), r.planet_pass, 1e-4);
  near(k.bearing_hz("b5", r.rotor_rpm)->bpfo_hz, r.b5_bpfo, 1e-3);
  near(k.bearing_hz("b5", r.rotor_rpm)->bpfi_hz, r.b5_bpfi, 1e-3);
  near(k.bearing_hz("b6", r.rotor_rpm)->bpfo_hz, r.b6_bpfo, 1e-3);
  near(k.bearing_hz("b6", r.rotor_rpm)->bpfi_hz, r.b6_bpfi, 1e-3);
  near(k.bearing_hz("b3", r.rotor_rpm)->bpfo_hz, r.b3_bpfo, 1e-3);
  near(k.bearing_hz("b3", r.rotor_rpm)->bpfi_hz, r.b3_bpfi, 1e-3);
}

TEST(Kinematics, MatchesTheReferenceTableAtThePaperOperatingPoint) { expect_row(kPaperPoint); }

TEST(Kinematics, MatchesTheReferenceTableAtRatedSpeed) { expect_row(kRated); }

TEST(Kinematics, OverallRatioIsTheProductOfTheToothRatios) {
  const model::Drivetrain d = model::paper_2mw();
  const model::Kinematics k(d);
  EXPECT_NEAR(k.overall_ratio(), (1.0 + 99.0 / 21.0) * (92.0 / 21.0) * (107.0 / 26.0), 1e-12);
  EXPECT_NEAR(k.overall_ratio(), 103.0246, 1e-4);
}

TEST(Kinematics, UnknownShaftOrBearingGivesNoValue) {
  const model::Drivetrain d = model::paper_2mw();
  const model::Kinematics k(d);
  EXPECT_FALSE(k.shaft_hz("gearbox", 10.0).has_value());
  EXPECT_FALSE(k.bearing_hz("b9", 10.0).has_value());
}

TEST(BearingOrders, DeepGrooveBallBearingMatchesTheCwruPublishedMultiples) {
  // SKF 6205 (shared/data/README.md): 9 balls, d = 7.94 mm, Dp = 39.04 mm, φ = 0;
  // published multiples of shaft speed: BPFI 5.4152, BPFO 3.5848, FTF 0.39828, BSF 2.3357.
  model::Bearing b;
  b.elements = 9;
  b.element_diameter_m = 0.3126 * 25.4e-3;
  b.pitch_diameter_m = 1.537 * 25.4e-3;
  const model::BearingFrequencies o = model::bearing_orders(b);
  EXPECT_NEAR(o.bpfi_hz, 5.4152, 1e-3);
  EXPECT_NEAR(o.bpfo_hz, 3.5848, 1e-3);
  EXPECT_NEAR(o.ftf_hz, 0.39828, 1e-4);
  // CWRU's BSF is 0.9 % below the textbook formula the reference prescribes
  // (their table rounds the ball and pitch diameters differently): 1 % band.
  EXPECT_NEAR(o.bsf_hz, 2.3357, 0.01 * 2.3357);
}

}  // namespace
