// ISO 6336-1 method C face load factor K_Hβ (and K_Fβ = K_Hβ^N_F) of paper-2mw's meshes
// at rated torque, against hand calculations written out below (lengths in mm, forces in N,
// deviations in µm; see model/fatigue/gear_rating.hpp for the equations and inputs).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "model/fatigue/drivetrain_channels.hpp"
#include "model/fatigue/gear_rating.hpp"

namespace {
using namespace model::fatigue;

std::size_t mesh_slot(const ChannelSet& cs, const std::string& id) {
  for (std::size_t m = 0; m < cs.mesh_count(); ++m) {
    if (cs.mesh_id(m) == id) return m;
  }
  ADD_FAILURE() << "no mesh " << id;
  return 0;
}

TEST(FaceLoadFactor, SunPlanetMeshAtRatedTorqueMatchesTheMethodCHandCalculation) {
  // Arrange: paper-2mw, defaults: helix correction (B1 = 0.1, B2 = 1), f_ma = f_Hβ, grade 6,
  // case-hardened, c_γβ = 0.85·20 = 17 N/(mm·µm).
  const ChannelSet cs(model::paper_2mw(), ChannelOptions{});
  ASSERT_TRUE(cs.valid()) << cs.error();
  const std::size_t slot = mesh_slot(cs, "sun-planet1");
  const double ft_n =
      1.23e6 / (1.0 + 99.0 / 21.0) / (3.0 * 0.1785);  // 401 960.78 N per planet mesh

  // Act
  const FaceLoad f = cs.mesh(slot).face_load(ft_n);

  // Hand calculation:
  //  F_m/b = 401 960.78/370 = 1086.3805 N/mm (K_A = K_v = 1)
  //  sun body: torsion of 3 planet meshes, no shaft bending (radial forces balance):
  //  γ = (|3 − 0.3| + 0.3)·(370/357)² = 3.222465;  f_sh = 0.023·γ·F_m/b = 80.5189 µm
  //  f_Hβ (grade 6, planet d = 663, b = 370) = (0.07·√663 + 0.45·√370 + 3)·√2 = 19.03296 µm = f_ma
  //  F_βx = 1.33·0.1·80.5189 + 1·19.03296 = 29.74198 µm (≥ max(0.005·1086.38, 0.5·19.03) = 9.52)
  //  y_β = 0.15·29.74198 = 4.461298 µm (≤ 6);  F_βy = 25.28069 µm
  //  K_Hβ = 1 + 17·25.28069/(2·1086.3805) = 1.197800 (≤ 2: linear branch)
  //  K_Fβ = 1.197800^N_F, b/h = 370/38.25, N_F = 0.897613 → 1.175868
  EXPECT_NEAR(f.line_load_n_mm, 1086.3805, 1e-4);
  EXPECT_NEAR(f.f_sh_um, 80.5189, 1e-4);
  EXPECT_NEAR(cs.mesh(slot).f_h_beta_um, 19.03296, 1e-5);
  EXPECT_NEAR(f.f_beta_x_um, 29.74198, 1e-5);
  EXPECT_NEAR(f.y_beta_um, 4.461298, 1e-6);
  EXPECT_NEAR(f.f_beta_y_um, 25.28069, 1e-5);
  EXPECT_NEAR(f.k_h_beta, 1.197800, 1e-6);
  EXPECT_NEAR(f.k_f_beta, 1.175868, 1e-6);
}

TEST(FaceLoadFactor, UnmodifiedIntermediatePinionTakesTheSquareRootBranchWithTheRunInCap) {
  // Arrange: no lead modification (B1 = B2 = 1); g2 on the ims (l = 1000 mm, d_sh = 220 mm).
  ChannelOptions o;
  o.rating.face_load.lead = LeadModification::kNone;
  const ChannelSet cs(model::paper_2mw(), o);
  ASSERT_TRUE(cs.valid()) << cs.error();
  const std::size_t slot = mesh_slot(cs, "g1-g2");
  // Sun-shaft torque 215 250 N·m on g1 (d = 92·14/cos10° = 1307.8695 mm): F_t = 329 161.29 N.
  const double ft_n =
      1.23e6 / (1.0 + 99.0 / 21.0) / (0.5 * 92 * 14e-3 / std::cos(10 * std::numbers::pi / 180));

  // Act
  const FaceLoad f = cs.mesh(slot).face_load(ft_n);

  // Hand calculation:
  //  F_m/b = 329 161.29/300 = 1097.2043 N/mm; pinion d1 = 21·14/cos10° = 298.5354 mm
  //  d1/d_sh = 1.357 ≥ 1.15 → K' = 0.48; s = 0.25·1000 = 250 mm
  //  K'·l·s/d1²·(d1/d_sh)⁴ = 0.48·1000·250/298.5354²·(298.5354/220)⁴ = 4.565436
  //  γ = (|1 + 4.565436 − 0.3| + 0.3)·(300/298.5354)² = 5.620177; f_sh = 0.023·γ·1097.2043 =
  //  141.8291 µm f_Hβ (wheel d = 1307.87, b = 300) = (0.07·√1307.87 + 0.45·√300 + 3)·√2 = 18.84545
  //  µm F_βx = 1.33·141.8291 + 18.84545 = 207.4781 µm; y_β = min(0.15·207.48, 6) = 6 µm (cap) F_βy
  //  = 201.4781 µm; 1 + 17·201.4781/(2·1097.2043) = 2.5608 > 2 → K_Hβ = √(2·17·201.4781/1097.2043)
  //  = 2.498674
  EXPECT_NEAR(f.f_sh_um, 141.8291, 1e-4);
  EXPECT_NEAR(f.f_beta_x_um, 207.4781, 1e-4);
  EXPECT_DOUBLE_EQ(f.y_beta_um, 6.0);
  EXPECT_NEAR(f.k_h_beta, 2.498674, 1e-6);
}

TEST(FaceLoadFactor, HelixCorrectionBringsTheSameMeshBackToTheLinearBranch) {
  // Same mesh, default helix correction: F_βx = 1.33·0.1·141.8291 + 18.84545 = 37.70872 µm,
  // y_β = 5.656308, F_βy = 32.05241, K_Hβ = 1 + 17·32.05241/(2·1097.2043) = 1.248309.
  const ChannelSet cs(model::paper_2mw(), ChannelOptions{});
  const std::size_t slot = mesh_slot(cs, "g1-g2");
  const double ft_n =
      1.23e6 / (1.0 + 99.0 / 21.0) / (0.5 * 92 * 14e-3 / std::cos(10 * std::numbers::pi / 180));
  EXPECT_NEAR(cs.mesh(slot).face_load(ft_n).k_h_beta, 1.248309, 1e-6);
}

TEST(FaceLoadFactor, VerifiedContactPatternUsesCorrigendumEquation53AndItsFloorForTheSun) {
  // Arrange: as the first test, but a verified favourable contact pattern: ISO 6336-1:2006
  // §7.5.2.3 eq. (53) as replaced by Cor.1:2008, F_βx = 1.33·B1·f_sh − f_Hβ5 ≥ F_βx,min.
  ChannelOptions o;
  o.rating.face_load.contact_pattern_verified = true;
  const ChannelSet cs(model::paper_2mw(), o);
  ASSERT_TRUE(cs.valid()) << cs.error();
  const std::size_t slot = mesh_slot(cs, "sun-planet1");
  const double ft_n = 1.23e6 / (1.0 + 99.0 / 21.0) / (3.0 * 0.1785);

  // Act
  const FaceLoad f = cs.mesh(slot).face_load(ft_n);

  // Hand calculation (F_m/b = 1086.3805 N/mm, f_sh = 80.51894 µm as above):
  //  f_Hβ5 = 0.07·√663 + 0.45·√370 + 3 = 1.802415 + 8.655923 + 3 = 13.458338 µm (grade 5)
  //  1.33·0.1·80.51894 − 13.458338 = −2.749318 µm: below F_βx,min
  //  F_βx,min = max(0.005·1086.3805, 0.5·19.032964) = 9.516482 µm = F_βx
  //  y_β = 0.15·9.516482 = 1.427472 µm;  F_βy = 8.089010 µm
  //  K_Hβ = 1 + 17·8.089010/(2·1086.3805) = 1.063290
  EXPECT_NEAR(cs.mesh(slot).f_h_beta5_um, 13.458338, 1e-6);
  EXPECT_NEAR(f.f_beta_x_um, 9.516482, 1e-6);
  EXPECT_NEAR(f.f_beta_y_um, 8.089010, 1e-6);
  EXPECT_NEAR(f.k_h_beta, 1.063290, 1e-6);
}

TEST(FaceLoadFactor, VerifiedContactPatternSubtractsFHbeta5WhenTheDeflectionTermDominates) {
  // Arrange: sun–planet without lead modification (B1 = 1), verified contact pattern.
  ChannelOptions o;
  o.rating.face_load.lead = LeadModification::kNone;
  o.rating.face_load.contact_pattern_verified = true;
  const ChannelSet cs(model::paper_2mw(), o);
  const std::size_t slot = mesh_slot(cs, "sun-planet1");
  const double ft_n = 1.23e6 / (1.0 + 99.0 / 21.0) / (3.0 * 0.1785);

  // Act
  const FaceLoad f = cs.mesh(slot).face_load(ft_n);

  // Hand calculation: F_βx = 1.33·1·80.51894 − 13.458338 = 93.631857 µm (> 9.516482);
  //  y_β = min(0.15·93.63, 6) = 6 µm; F_βy = 87.631857 µm;
  //  K_Hβ = 1 + 17·87.631857/(2·1086.3805) = 1.685644 (≤ 2: linear branch)
  EXPECT_NEAR(f.f_beta_x_um, 93.631857, 1e-5);
  EXPECT_DOUBLE_EQ(f.y_beta_um, 6.0);
  EXPECT_NEAR(f.k_h_beta, 1.685644, 1e-6);
}

TEST(FaceLoadFactor, OverrideIsUsedAtEveryLoadAndEntersTheContactStressUnderTheRoot) {
  // Arrange
  ChannelOptions fixed;
  fixed.rating.k_h_beta_override = 1.3;
  const ChannelSet a(model::paper_2mw(), fixed);
  fixed.rating.k_h_beta_override = 1.3 * 1.21;
  const ChannelSet b(model::paper_2mw(), fixed);
  const std::size_t slot = mesh_slot(a, "sun-planet1");
  // Act / Assert: constant at any load; σ_H ∝ √K_Hβ, so ×1.21 in K_Hβ is ×1.1 in σ_H.
  EXPECT_DOUBLE_EQ(a.mesh(slot).face_load(1e3).k_h_beta, 1.3);
  EXPECT_DOUBLE_EQ(a.mesh(slot).face_load(1e6).k_h_beta, 1.3);
  EXPECT_NEAR(b.mesh(slot).contact_stress_mpa(4e5, 0) / a.mesh(slot).contact_stress_mpa(4e5, 0),
              1.1, 1e-12);
}

TEST(FaceLoadFactor, ContactStressStillVanishesAtZeroLoadAndGrowsWithLoad) {
  // The √ branch grows as (F_m/b)^-½ at small loads; F_t·K_Hβ must still go to 0.
  const ChannelSet cs(model::paper_2mw(), ChannelOptions{});
  const std::size_t slot = mesh_slot(cs, "sun-planet1");
  const MeshRating& r = cs.mesh(slot);
  EXPECT_LT(r.contact_stress_mpa(0.0, 0), 1.0);
  double last = r.contact_stress_mpa(1.0, 0);
  for (double ft = 10.0; ft < 1e6; ft *= 3.0) {
    const double s = r.contact_stress_mpa(ft, 0);
    EXPECT_GT(s, last) << "F_t = " << ft;
    last = s;
  }
}

TEST(FaceLoadFactor, LeadModificationNamesRoundTripAndUnknownNamesAreRefused) {
  for (auto m : {LeadModification::kNone, LeadModification::kHelixCorrection,
                 LeadModification::kHelixCorrectionAndCrowning, LeadModification::kCrowning,
                 LeadModification::kEndRelief}) {
    EXPECT_EQ(parse_lead_modification(lead_modification_name(m)), m);
  }
  EXPECT_FALSE(parse_lead_modification("barrel").has_value());
}

}  // namespace
