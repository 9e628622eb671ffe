// ISO 6336-2 contact stress and ISO 6336-3 (method B) root stress of the sun–planet
// mesh of paper-2mw at rated rotor torque, against a hand calculation written out
// step by step below (ISO 6336:2006 equation numbers; lengths in mm, forces in N).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "model/fatigue/drivetrain_channels.hpp"
#include "model/fatigue/gear_rating.hpp"

namespace {
using namespace model::fatigue;
constexpr double kDeg = std::numbers::pi / 180.0;

// Sun–planet: m_n = 17 mm, α_n = 20°, β = 0, z1 = 21 (sun), z2 = 39 (planet), x = 0, b = 370 mm.
PairGeometry sun_planet() {
  return pair_geometry(21, 39, 0, 0, 17e-3, 20 * kDeg, 0.0, 0.370, BasicRack{});
}

TEST(GearGeometry, SunPlanetContactRatioMatchesTheHandCalculation) {
  // d1 = 21·17 = 357, d2 = 663; d_b = d·cos20° = 335.4703, 623.0162; d_a = d + 2·17 = 391, 697;
  // a = 510; g_α = ½(√(391² − 335.4703²) + √(697² − 623.0162²)) − 510·sin20° = 82.2475;
  // p_bt = π·17·cos20° = 50.1862; ε_α = g_α/p_bt = 1.63885.
  const PairGeometry g = sun_planet();
  EXPECT_NEAR(g.db_m[0] * 1e3, 335.4703, 1e-4);
  EXPECT_NEAR(g.a_w_m * 1e3, 510.0, 1e-9);
  EXPECT_NEAR(g.eps_alpha, 1.63885, 1e-5);
  EXPECT_DOUBLE_EQ(g.eps_beta, 0.0);
}

TEST(ContactStress, SunAtRatedTorqueMatchesTheIso6336Part2HandCalculation) {
  // Arrange: rated rotor torque 1.23e6 N·m, ring fixed: sun torque T_s = T_c/(1 + 99/21)
  // = 215 250 N·m; per planet F_t = T_s/(3·0.1785 m) = 401 960.78 N.
  const double ft_n = 1.23e6 / (1.0 + 99.0 / 21.0) / (3.0 * 0.1785);
  ASSERT_NEAR(ft_n, 401960.78, 0.01);
  const model::Material steel{};
  RatingSettings s;  // ISO 1328 class 6; K_Hβ fixed here (method C has its own tests below)
  s.k_h_beta_override = 1.15;
  const MeshRating r = mesh_rating(sun_planet(), steel, steel, 1.0, s);

  // Hand calculation:
  //  Z_H = √(2·cosβ_b·cosα_wt/(cos²α_t·sinα_wt)) = √(2/(cos20°·sin20°)) = 2.49457   (eq. 9)
  //  Z_E = √(1/(π·2·(1 − 0.3²)/206 000)) = 189.812 √(N/mm²)                         (eq. 22)
  //  Z_ε = √((4 − ε_α)/3) = √((4 − 1.63885)/3) = 0.887159                           (eq. 34)
  //  Z_β = 1/√cos 0 = 1                                                                 (§9)
  //  M1 = tan20°/√((√(391²/335.4703² − 1) − 2π/21)·(√(697²/623.0162² − 1) − 0.63885·2π/39))
  //     = 0.363970/√((0.598712 − 0.299199)·(0.501601 − 0.102924)) = 1.053288 → Z_B = M1
  //  σ_H0 = Z_H·Z_E·Z_ε·Z_β·√(F_t/(d1·b)·(u+1)/u), u = 39/21
  //       = 2.49457·189.812·0.887159·√(401 960.78/(357·370)·(60/39)) = 908.910 N/mm²   (eq. 2)
  //  K_Hα (ISO 6336-1 eq. 75): f_pt(class 6) = (0.001·663 + 0.4·17 + 5)·√2 = 17.6253 µm,
  //       f_pb = f_pt·cos20° = 16.5624, y_α = 0.075·f_pb = 1.24218,
  //       ε_γ/2·(0.9 + 0.4·20·(16.5624 − 1.24218)/(401 960.78·1.15/370)) = 0.81787 < 1 → K_Hα = 1
  //  σ_H = Z_B·σ_H0·√(K_A·K_v·K_Hβ·K_Hα) = 1.053288·908.910·√1.15 = 1026.637 N/mm²     (eq. 3)
  EXPECT_NEAR(r.z_h, 2.49457, 1e-5);
  EXPECT_NEAR(r.z_e_sqrt_mpa, 189.812, 1e-3);
  EXPECT_NEAR(r.z_eps, 0.887159, 1e-6);
  EXPECT_DOUBLE_EQ(r.z_beta, 1.0);
  EXPECT_NEAR(r.z_b, 1.053288, 1e-6);
  EXPECT_NEAR(r.contact_stress_nominal_mpa(ft_n), 908.910, 1e-3);
  EXPECT_DOUBLE_EQ(r.k_alpha(ft_n), 1.0);
  EXPECT_NEAR(r.contact_stress_mpa(ft_n, 0), 1026.637, 1e-3);
}

TEST(ContactStress, ScalesWithTheSquareRootOfTheForceAboveTheKHalphaFloorAtConstantKHbeta) {
  const model::Material steel{};
  RatingSettings s;
  s.k_h_beta_override = 1.15;
  const MeshRating r = mesh_rating(sun_planet(), steel, steel, 1.0, s);
  const double f = 4e5;
  EXPECT_NEAR(r.contact_stress_mpa(4.0 * f, 0) / r.contact_stress_mpa(f, 0), 2.0, 1e-12);
}

TEST(BendingStress, SunRootStressMatchesTheIso6336Part3MethodBHandCalculation) {
  // Arrange
  const double ft_n = 1.23e6 / (1.0 + 99.0 / 21.0) / (3.0 * 0.1785);
  const model::Material steel{};
  RatingSettings s;
  s.k_h_beta_override = 1.15;  // method C has its own tests below
  const MeshRating r = mesh_rating(sun_planet(), steel, steel, 1.0, s);
  // Hand calculation, ISO 6336-3:2006 method B, sun z = 21, x = 0, rack h_fP = 21.25,
  // ρ_fP = 6.46 (ISO 53 A), z_n = 21:
  //  E = π/4·17 − 21.25·tan20° − (1 − sin20°)·6.46/cos20° = 1.094061 mm          (eq. 35)
  //  G = 0.38 − 1.25 + 0 = −0.87                                                 (eq. 36)
  //  H = 2/21·(π/2 − 1.094061/17) − π/3 = −0.903727                              (eq. 37)
  //  θ = 2G/z_n·tanθ − H → θ = 0.815691 rad (46.736°)                            (eq. 38)
  //  s_Fn = 17·(21·sin(60° − θ) + √3·(G/cosθ − 0.38)) = 33.3451 mm               (eq. 39)
  //  ρ_F = 17·(0.38 + 2G²/(cosθ·(21·cos²θ − 2G))) = 9.69578 mm                   (eq. 40)
  //  d_en = 2·√((√(391²/4 − 335.4703²/4) − 50.1862·0.63885)² + 335.4703²/4) = 362.2632 mm (eq. 47)
  //  α_en = acos(335.4703/362.2632) = 0.387014; γ_e = (π/2)/21 + inv20° − inv α_en = 0.0691495;
  //  α_Fen = 0.317865 rad                                                         (eq. 48–50)
  //  h_Fe = 8.5·((cosγ_e − sinγ_e·tanα_Fen)·362.2632/17 − 21·cos(60° − θ) − G/cosθ + 0.38)
  //       = 16.8629 mm                                                            (eq. 41)
  //  Y_F = 6·(h_Fe/m_n)·cosα_Fen/((s_Fn/m_n)²·cos20°) = 1.563728                 (eq. 33)
  //  L = s_Fn/h_Fe = 1.977428, q_s = s_Fn/(2ρ_F) = 1.719570,
  //  Y_S = (1.2 + 0.13·L)·q_s^(1/(1.21 + 2.3/L)) = 1.830971                       (eq. 45)
  //  K_Fβ = 1.15^N_F, b/h = 370/38.25 = 9.673203, N_F = (b/h)²/(1 + b/h + (b/h)²) = 0.897613,
  //  K_Fβ = 1.133661 (ISO 6336-1 eq. 73); Y_β = 1 (spur); K_Fα = 1 as for K_Hα.
  //  σ_F = F_t/(b·m_n)·Y_F·Y_S·Y_β·K_Fβ·K_Fα = 401 960.78/(370·17)·1.563728·1.830971·1.133661
  //      = 207.424 N/mm²
  const BendingFormFactors& f = r.bending[0];
  EXPECT_NEAR(f.s_fn_m * 1e3, 33.3451, 1e-4);
  EXPECT_NEAR(f.rho_f_m * 1e3, 9.69578, 1e-5);
  EXPECT_NEAR(f.h_fe_m * 1e3, 16.8629, 1e-4);
  EXPECT_NEAR(f.alpha_fen_rad, 0.317865, 1e-6);
  EXPECT_NEAR(f.y_f, 1.563728, 1e-6);
  EXPECT_NEAR(f.y_s, 1.830971, 1e-6);
  EXPECT_NEAR(r.face_load(ft_n).k_f_beta, 1.133661, 1e-6);
  EXPECT_NEAR(r.bending_stress_mpa(ft_n, 0), 207.424, 1e-3);
}

TEST(BendingStress, InternalRingGearIsNotRatedAndReportsZero) {
  const model::Material steel{};
  const PairGeometry g = pair_geometry(39, -99, 0, 0, 17e-3, 20 * kDeg, 0.0, 0.370, BasicRack{});
  const MeshRating r = mesh_rating(g, steel, steel, 1.0, RatingSettings{});
  EXPECT_TRUE(r.bending_rated[0]);
  EXPECT_FALSE(r.bending_rated[1]);
  EXPECT_DOUBLE_EQ(r.bending_stress_mpa(1e5, 1), 0.0);
  // Internal pair: (u+1)/u with u = −99/39 gives (99 − 39)/99; Z_D = 1 (ISO 6336-2 §6.2).
  EXPECT_DOUBLE_EQ(r.z_d, 1.0);
}

TEST(HelicalMesh, OverlapRatioAndHelixFactorsFollowTheHelixAngle) {
  // g1–g2: m_n = 14 mm, β = 10°, b = 300 mm: ε_β = 300·sin10°/(π·14) = 1.184441 ≥ 1,
  // so Z_ε = √(1/ε_α), Z_B = 1 and Y_β = 1 − 1·10/120 = 0.916667; Z_β = 1/√cos10° = 1.007684
  // (ISO 6336-2:2006 §9; the DIN 3990 form √cos β would give 0.992375).
  const model::Material steel{};
  const PairGeometry g =
      pair_geometry(21, 92, 0, 0, 14e-3, 20 * kDeg, 10 * kDeg, 0.300, BasicRack{});
  const MeshRating r = mesh_rating(g, steel, steel, 1.0, RatingSettings{});
  EXPECT_NEAR(g.eps_beta, 1.184441, 1e-6);
  EXPECT_NEAR(r.z_eps, std::sqrt(1.0 / g.eps_alpha), 1e-12);
  EXPECT_DOUBLE_EQ(r.z_b, 1.0);
  EXPECT_NEAR(r.y_beta, 0.916667, 1e-6);
  EXPECT_NEAR(r.z_beta, 1.007684, 1e-6);
}

TEST(DrivetrainChannels, PaperTurbineHasEveryGearModeAndBearingWithDerivedCycleCounts) {
  const model::Drivetrain d = model::paper_2mw();
  const ChannelSet cs(d, ChannelOptions{});
  ASSERT_TRUE(cs.valid()) << cs.error();
  // 3 sun–planet + 3 planet–ring + 2 parallel meshes; 6 shaft bearings + 3 planet bearings.
  EXPECT_EQ(cs.mesh_count(), 8u);
  EXPECT_EQ(cs.bearing_count(), 9u);
  // Sun contact: one source per planet, z_r/z_s = 99/21 cycles per carrier revolution each,
  // 3·99/21 = 14.142857 in all (relative to the carrier).
  const Channel& sun = cs.channel(0);
  EXPECT_EQ(sun.component, "sun");
  EXPECT_EQ(sun.source_count, 3u);
  double total = 0.0;
  for (std::size_t k = 0; k < sun.source_count; ++k) total += sun.sources[k].cycles_per_rotor_rev;
  EXPECT_NEAR(total, 3.0 * 99.0 / 21.0, 1e-12);
  // g4 on the hss: one contact per own revolution = overall ratio 103.0246 per rotor rev.
  bool found_g4 = false;
  for (std::size_t c = 0; c < cs.channel_count(); ++c) {
    const Channel& ch = cs.channel(c);
    if (ch.component == "g4" && ch.mode == FailureMode::kContact) {
      found_g4 = true;
      EXPECT_NEAR(ch.sources[0].cycles_per_rotor_rev, (1 + 99.0 / 21) * (92.0 / 21) * (107.0 / 26),
                  1e-9);
    }
    if (ch.component == "ring") {
      EXPECT_NEAR(ch.sources[0].cycles_per_rotor_rev, 1.0, 1e-12);
    }
    if (ch.component == "planet1" && ch.mode == FailureMode::kContact) {
      EXPECT_NEAR(ch.sources[0].cycles_per_rotor_rev, 99.0 / 39.0, 1e-12);
    }
  }
  EXPECT_TRUE(found_g4);
}

TEST(DrivetrainChannels, UnknownMaterialIsReportedByGearAndMaterialName) {
  model::Drivetrain d = model::paper_2mw();
  d.gears[2].material = "unobtainium";
  const ChannelSet cs(d, ChannelOptions{});
  EXPECT_FALSE(cs.valid());
  EXPECT_NE(cs.error().find("sun"), std::string::npos);
  EXPECT_NE(cs.error().find("unobtainium"), std::string::npos);
}

}  // namespace
