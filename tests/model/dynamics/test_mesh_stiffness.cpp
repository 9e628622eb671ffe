// Gear-mesh geometry and stiffness against hand calculations (ISO 21771 contact
// ratios, ISO 6336-1 §9 method B stiffness) and against properties of the
// contact-line model that hold whatever the implementation.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "model/dynamics/bearing_compliance.hpp"
#include "model/dynamics/mesh_stiffness.hpp"

namespace {

using model::dynamics::GearPair;
using model::dynamics::PeriodicTable;
constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

GearPair sun_planet() { return {21, 39, false, 0.017, 20 * kDeg, 0.0, 0.370, 0.0, 0.0}; }
GearPair planet_ring() { return {39, 99, true, 0.017, 20 * kDeg, 0.0, 0.370, 0.0, 0.0}; }
GearPair intermediate() { return {21, 92, false, 0.014, 20 * kDeg, 10 * kDeg, 0.300, 0.0, 0.0}; }

TEST(ContactRatio, SunPlanetSpurMeshMatchesTheHandCalculation) {
  // Arrange: m = 17 mm, α = 20°, z = 21/39, addendum = m.
  // r_b1 = 178.5·cos20° = 167.736 mm, r_a1 = 195.5 mm; r_b2 = 331.5·cos20° = 311.512 mm,
  // r_a2 = 348.5 mm; a = 510 mm; p_b = π·17·cos20° = 50.186 mm.
  // ε_α = (√(195.5² − 167.736²) + √(348.5² − 311.512²) − 510·sin20°) / 50.186
  //     = (100.425 + 156.253 − 174.430) / 50.186 = 1.6388
  // Act
  const auto g = model::dynamics::mesh_geometry(sun_planet());
  // Assert
  EXPECT_NEAR(g.transverse_contact_ratio, 1.6388, 2e-4);
  EXPECT_DOUBLE_EQ(g.overlap_ratio, 0.0);
  EXPECT_NEAR(g.base_pitch_m, 0.050186, 1e-6);
}

TEST(ContactRatio, PlanetRingInternalMeshMatchesTheHandCalculation) {
  // Internal gear: the ring's tip circle is inside its pitch circle, r_a2 = 841.5 − 17 = 824.5 mm,
  // r_b2 = 841.5·cos20° = 790.751 mm, a = 841.5 − 331.5 = 510 mm;
  // ε_α = (√(348.5² − 311.512²) − √(824.5² − 790.751²) + 510·sin20°) / 50.186
  //     = (156.253 − 233.479 + 174.430) / 50.186 = 1.9369
  const auto g = model::dynamics::mesh_geometry(planet_ring());
  EXPECT_NEAR(g.transverse_contact_ratio, 1.9369, 2e-4);
}

TEST(ContactRatio, HelicalIntermediateMeshHasTransverseAndOverlapRatios) {
  // m_n = 14 mm, β = 10°: m_t = 14/cos10° = 14.2158 mm, α_t = atan(tan20°/cos10°) = 20.284°.
  // Transverse ratio by the same formula with transverse quantities: ε_α = 1.6691.
  // ε_β = b·sinβ / (π m_n) = 300·sin10° / (π·14) = 1.1844.
  const auto g = model::dynamics::mesh_geometry(intermediate());
  EXPECT_NEAR(g.transverse_pressure_angle_rad / kDeg, 20.284, 1e-3);
  EXPECT_NEAR(g.transverse_contact_ratio, 1.6691, 2e-4);
  EXPECT_NEAR(g.overlap_ratio, 1.1844, 1e-4);
}

TEST(IsoStiffness, SingleAndMeshStiffnessFollowMethodBOfIso6336) {
  // q' = 0.04723 + 0.15551/21 + 0.25791/39 = 0.061249 mm·µm/N → c'_th = 16.327 N/(mm·µm);
  // c' = c'_th·C_M·C_R·C_B = 16.327·0.8·1·0.975 = 12.735; c_γα = c'·(0.75·1.6388 + 0.25) = 18.837.
  EXPECT_NEAR(model::dynamics::iso_single_pair_stiffness(sun_planet()), 12.735, 1e-3);
  EXPECT_NEAR(model::dynamics::iso_mesh_stiffness(sun_planet()), 18.837, 1e-3);
  // The mean mesh stiffness of the stage: c_γα·b = 18.837 N/(mm·µm)·370 mm = 6.970e9 N/m.
  EXPECT_NEAR(model::dynamics::mesh_stiffness(sun_planet()).mean_n_m, 6.970e9, 0.001e9);
}

TEST(MeshStiffnessShape, SpurMeshAlternatesBetweenOneAndTwoPairsForTheContactRatioFraction) {
  // Arrange
  const auto g = model::dynamics::mesh_geometry(sun_planet());
  const auto k = model::dynamics::mesh_stiffness(sun_planet());
  // Act: samples with two pairs in contact are those above the mean.
  const auto& v = k.shape.values;
  const double lo = *std::min_element(v.begin(), v.end());
  const double hi = *std::max_element(v.begin(), v.end());
  const auto doubles =
      std::count_if(v.begin(), v.end(), [&](double x) { return x > 0.5 * (lo + hi); });
  // Assert: stiffness ratio 2:1 (rectangular single/double contact), double contact for
  // (ε_α − 1) of the cycle, and the shape has mean 1 (the ISO mean is kept).
  EXPECT_NEAR(hi / lo, 2.0, 1e-12);
  EXPECT_NEAR(static_cast<double>(doubles) / PeriodicTable::kSize, g.transverse_contact_ratio - 1.0,
              1.5 / PeriodicTable::kSize);
  EXPECT_NEAR(k.shape.mean(), 1.0, 1e-12);
}

TEST(MeshStiffnessShape, HelicalContactLinesAverageToTransverseContactRatioTimesFaceWidth) {
  // The mean contact-line length of any involute helical pair is ε_α·b/cos β_b
  // (each pair sweeps the plane of action once per ε_α base pitches).
  const auto pair = intermediate();
  const auto g = model::dynamics::mesh_geometry(pair);
  double sum = 0.0;
  constexpr int kSamples = 4000;
  for (int i = 0; i < kSamples; ++i) {
    sum += model::dynamics::contact_line_length_m(g, pair.face_width_m,
                                                  static_cast<double>(i) / kSamples);
  }
  EXPECT_NEAR(sum / kSamples,
              g.transverse_contact_ratio * pair.face_width_m / std::cos(g.base_helix_angle_rad),
              1e-3 * pair.face_width_m);
}

TEST(MeshStiffnessShape, HelicalMeshVariesLessThanTheSpurMesh) {
  const auto spur = model::dynamics::mesh_stiffness(sun_planet());
  const auto helical = model::dynamics::mesh_stiffness(intermediate());
  auto range = [](const PeriodicTable& t) {
    return *std::max_element(t.values.begin(), t.values.end()) -
           *std::min_element(t.values.begin(), t.values.end());
  };
  EXPECT_LT(range(helical.shape), 0.25 * range(spur.shape));
  EXPECT_GT(range(helical.shape), 0.0);
}

// Tip relief (contact_line_length_m): each pair's contact is weighted by a ramp of length
// L = r·(g_α − p_bt) at both ends of the path, so a spur mesh's contact length is a periodic
// sum of trapezoids (support g_α, plateau g_α − 2L) spaced one base pitch apart: a box of
// width g_α − L convolved with a unit-area box of width L. Its Fourier coefficients are
// therefore c_k/c_0 = sinc(π k (g_α − L)/p_bt) · sinc(π k L/p_bt), sinc x = sin x / x.
double sinc(double x) { return x == 0.0 ? 1.0 : std::sin(x) / x; }

/// Amplitude of harmonic k of a table (a cosine of amplitude A gives A).
double harmonic(const PeriodicTable& t, int k) {
  double re = 0.0, im = 0.0;
  for (std::size_t i = 0; i < PeriodicTable::kSize; ++i) {
    const double a = 2.0 * kPi * k * static_cast<double>(i) / PeriodicTable::kSize;
    re += t.values[i] * std::cos(a);
    im += t.values[i] * std::sin(a);
  }
  return 2.0 * std::hypot(re, im) / PeriodicTable::kSize;
}

TEST(MeshStiffnessShape, SpurTipReliefTurnsTheRectangularWaveIntoTheTrapezoidsHarmonics) {
  const auto pair = sun_planet();
  const auto g = model::dynamics::mesh_geometry(pair);
  const double p = g.base_pitch_m;
  for (const double r : {0.25, 0.5, 0.75}) {
    const double ramp = r * (g.path_of_contact_m - p);
    const auto k = model::dynamics::mesh_stiffness(pair, 1.0, r);
    for (int h = 1; h <= 6; ++h) {
      const double expected = 2.0 * std::abs(sinc(kPi * h * (g.path_of_contact_m - ramp) / p) *
                                             sinc(kPi * h * ramp / p));
      EXPECT_NEAR(harmonic(k.shape, h), expected, 2e-3) << "relief " << r << ", harmonic " << h;
    }
    // The mean contact length is the trapezoid's area per pitch: b·(g_α − L)/p_bt.
    double sum = 0.0;
    for (int i = 0; i < 1000; ++i) {
      sum += model::dynamics::contact_line_length_m(g, pair.face_width_m, i / 1000.0, r);
    }
    EXPECT_NEAR(sum / 1000.0, pair.face_width_m * (g.path_of_contact_m - ramp) / p,
                1e-3 * pair.face_width_m);
  }
}

TEST(MeshStiffnessShape, FullTipReliefEvensTheStiffnessOutAndNoReliefLeavesItUnchanged) {
  // At r = 1 the ramps of successive pairs complement each other (L = g_α − p_bt): constant.
  for (const auto& pair : {sun_planet(), planet_ring(), intermediate()}) {
    const auto flat = model::dynamics::mesh_stiffness(pair, 1.0, 1.0);
    const auto [lo, hi] = std::minmax_element(flat.shape.values.begin(), flat.shape.values.end());
    EXPECT_LT(*hi - *lo, 1e-9);
    const auto none = model::dynamics::mesh_stiffness(pair, 1.0, 0.0);
    const auto plain = model::dynamics::mesh_stiffness(pair);
    EXPECT_EQ(none.shape.values, plain.shape.values);
    EXPECT_DOUBLE_EQ(flat.mean_n_m, plain.mean_n_m);  // the ISO 6336-1 mean is kept
  }
}

TEST(MeshPhasing, EquallySpacedPlanetsMeshInPhaseWhenToothCountsDivideByThePlanetCount) {
  // Parker & Lin 2004: γ_sn = z_s ψ_n / 2π mod 1. z_s = 21, ψ = 120°: 7 → 0.
  EXPECT_NEAR(model::dynamics::sun_planet_phase(21, 2 * kPi / 3), 0.0, 1e-9);
  EXPECT_NEAR(model::dynamics::ring_planet_phase(99, 2 * kPi / 3), 0.0, 1e-9);
  // z_s = 20: 20/3 = 6.667 → 2/3; ring 100: −100/3 = −33.333 → 2/3.
  EXPECT_NEAR(model::dynamics::sun_planet_phase(20, 2 * kPi / 3), 2.0 / 3.0, 1e-9);
  EXPECT_NEAR(model::dynamics::ring_planet_phase(100, 2 * kPi / 3), 2.0 / 3.0, 1e-9);
}

TEST(MeshPhasing, RingMeshLagsTheSunMeshByHalfACycleOnlyForAnEvenPlanet) {
  EXPECT_NEAR(model::dynamics::ring_sun_phase(39), 0.0, 1e-12);
  EXPECT_NEAR(model::dynamics::ring_sun_phase(40), 0.5, 1e-12);
}

TEST(PeriodicTableLookup, InterpolatesLinearlyAndWrapsAround) {
  PeriodicTable t = PeriodicTable::constant(0.0);
  t.values[0] = 1.0;
  t.values[1] = 3.0;
  const double step = 1.0 / PeriodicTable::kSize;
  EXPECT_DOUBLE_EQ(t.value(0.5 * step), 2.0);
  EXPECT_DOUBLE_EQ(t.value(-1.0 + 0.5 * step), 2.0);
  EXPECT_NEAR(t.value(1.0 - 0.5 * step), 0.5, 1e-9);  // last sample (0) → first (1)
}

}  // namespace

// ---- a bearing's varying compliance (bearing_compliance.hpp) ------------------------------

TEST(BearingCompliance, StiffnessAtTwoRollerPositionsMatchesTheLineContactLawByHand) {
  // b5 of paper-2mw: 16 cylindrical rollers, zero clearance, inner ring displaced by δ along
  // the load. Line contact Q = K_n·δ_j^(10/9) (Palmgren's δ ∝ Q^0.9/L^0.8), δ_j = δ·cos ψ_j:
  // F = K_n δ^(10/9) Σ cos^(19/9) ψ_j over the rollers with cos ψ_j > 0; the secant stiffness
  // F/δ at two cage positions, by hand:
  //  roller on the load line: ψ = 0, ±22.5°, ±45°, ±67.5° (±90° carries nothing)
  //    Σ = 1 + 2·(0.846078 + 0.481112 + 0.131622) = 3.917624
  //  half a pitch on:         ψ = ±11.25°, ±33.75°, ±56.25°, ±78.75°
  //    Σ = 2·(0.959868 + 0.677309 + 0.289145 + 0.031740) = 3.916124
  //  k(0)/k(½) − 1 = 3.917624/3.916124 − 1 = 3.83e-4: the 16-roller bearing's stiffness
  //  fluctuates by ~2e-4 about its mean at zero clearance, not by 10 %.
  const PeriodicTable t = model::dynamics::bearing_load_zone_force(16, model::BearingType::kRoller);
  EXPECT_NEAR(t.value(0.0) / t.value(0.5) - 1.0, 3.9176228 / 3.9161246 - 1.0, 2e-6);
  EXPECT_NEAR(t.mean(), 1.0, 1e-12);
  // The roller on the load line is the stiffest position for 16 rollers (an even count puts
  // one at ±90°, unloaded); for 14 (b6) the half-pitch position is: by hand
  // Σ(0) = 1 + 2·Σ_{k=1..3} cos^(19/9)(k·25.714°) = 3.426310,
  // Σ(½) = 2·Σ_{k=0..2} cos^(19/9)((k + ½)·25.714°) = 3.428306.
  const PeriodicTable t14 =
      model::dynamics::bearing_load_zone_force(14, model::BearingType::kRoller);
  EXPECT_NEAR(t14.value(0.0) / t14.value(0.5) - 1.0, 3.4263100 / 3.4283065 - 1.0, 2e-6);
}

TEST(BearingCompliance, TheModelsShapeScalesTheDerivedFluctuationAndAddsTheCosine) {
  const PeriodicTable f = model::dynamics::bearing_load_zone_force(16, model::BearingType::kRoller);
  const PeriodicTable none =
      model::dynamics::bearing_stiffness_shape(16, model::BearingType::kRoller, 0.0, 0.0);
  const PeriodicTable x30 =
      model::dynamics::bearing_stiffness_shape(16, model::BearingType::kRoller, 30.0, 0.05);
  for (double c : {0.0, 0.1, 0.25, 0.5, 0.8}) {
    EXPECT_DOUBLE_EQ(none.value(c), 1.0);
    EXPECT_NEAR(x30.value(c), 1.0 + 30.0 * (f.value(c) - 1.0) + 0.05 * std::cos(2.0 * kPi * c),
                1e-4);
  }
  // A ball's point contact (n = 3/2) fluctuates more than a roller's line contact at the same
  // count: the sum of cos^(n+1) over the load zone is less even.
  const PeriodicTable ball =
      model::dynamics::bearing_load_zone_force(16, model::BearingType::kBall);
  EXPECT_GT(ball.value(0.0) / ball.value(0.5), f.value(0.0) / f.value(0.5));
}
