// The effects of the diagnosis contract (model/drivetrain/effects.hpp) as terms of the
// dynamics models: the description API, where each effect can sit, the frequencies of the
// terms each one adds against the hand-computed kinematics of drivetrain-2mw.md, and the
// reduced model stepping with any of them switched on without allocating. Short: runs
// under qemu and the sanitizers (the full/ROM agreement is test_effects_fidelity.cpp).
// GCC 12 (with ASan) inlines the replaced operator delete below into gtest's code and then
// mistakes free() on operator new's malloc() for a mismatch; both are ours and match.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <complex>
#include <cstdlib>
#include <new>
#include <numbers>
#include <string>

#include "model/drivetrain/description.hpp"
#include "model/drivetrain/effects.hpp"
#include "model/dynamics/eigen_instances.hpp"
#include "model/dynamics/full_model.hpp"
#include "model/dynamics/rom.hpp"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

// Counting global allocator (test binary only).
void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace {

using namespace model::dynamics;
using model::EffectKind;
constexpr double kPi = std::numbers::pi;
constexpr double kPaperRpm = 8.33;
constexpr double kRotorHz = kPaperRpm / 60.0;  // 0.138833 Hz

model::Effect effect(EffectKind kind, const std::string& location,
                     std::initializer_list<std::pair<const char*, double>> params = {}) {
  model::Effect e = model::make_effect(kind, location);
  for (const auto& [name, value] : params) EXPECT_TRUE(e.set_parameter(name, value)) << name;
  return e;
}

FullModel model_with(std::initializer_list<model::Effect> effects) {
  model::Drivetrain d = model::paper_2mw();
  d.effects.assign(effects.begin(), effects.end());
  std::string error;
  std::optional<FullModel> m = build_full_model(d, {}, &error);
  EXPECT_TRUE(m.has_value()) << error;
  return m ? *m : FullModel{};
}

// The force terms an effect added (the model's first force is the input torque).
std::vector<const ForceTerm*> effect_forces(const FullModel& m) {
  std::vector<const ForceTerm*> out;
  for (std::size_t i = 1; i < m.forces.size(); ++i) out.push_back(&m.forces[i]);
  return out;
}

// |c_h| of a periodic table's Fourier series: which harmonics it carries.
double harmonic(const PeriodicTable& t, int h) {
  std::complex<double> c{0.0, 0.0};
  for (std::size_t i = 0; i < PeriodicTable::kSize; ++i) {
    const double x = 2.0 * kPi * h * static_cast<double>(i) / PeriodicTable::kSize;
    c += t.values[i] * std::complex<double>(std::cos(x), -std::sin(x));
  }
  return std::abs(c) / PeriodicTable::kSize;
}

TEST(Effects, EveryContractIdRoundTripsWithNamedBoundedParameters) {
  const char* ids[] = {"tooth_crack",
                       "gear_eccentricity",
                       "bearing_outer_race_defect",
                       "bearing_inner_race_defect",
                       "bearing_ball_defect",
                       "shaft_unbalance",
                       "shaft_misalignment",
                       "planet_pass_modulation",
                       "housing_resonance"};
  ASSERT_EQ(model::effect_kinds().size(), std::size(ids));
  for (const char* id : ids) {
    const auto kind = model::effect_kind(id);
    ASSERT_TRUE(kind) << id;
    EXPECT_EQ(model::effect_id(*kind), id);
    const auto params = model::effect_parameters(*kind);
    ASSERT_FALSE(params.empty()) << id;
    int fitted = 0;
    for (const auto& p : params) {
      EXPECT_LE(p.lower, p.default_value) << id << "." << p.name;
      EXPECT_GE(p.upper, p.default_value) << id << "." << p.name;
      fitted += p.fitted ? 1 : 0;
    }
    EXPECT_GE(fitted, 1) << id << ": a fit needs at least one parameter to vary";
  }
  EXPECT_FALSE(model::effect_kind("cracked_tooth"));
}

TEST(Effects, LocationsCoverEveryStageAndBothMeasuredShafts) {
  const model::Drivetrain d = model::paper_2mw();
  auto has = [&](EffectKind k, const char* where) {
    const auto l = model::effect_locations(d, k);
    return std::find(l.begin(), l.end(), where) != l.end();
  };
  for (const char* g : {"sun", "planet", "planet2", "g1", "g2", "g3", "g4"})
    EXPECT_TRUE(has(EffectKind::kToothCrack, g)) << g;
  for (const char* g : {"sun", "g1", "g2", "g3", "g4"})
    EXPECT_TRUE(has(EffectKind::kGearEccentricity, g)) << g;
  for (const char* b : {"b1", "b2", "b3", "b4", "b5", "b6", "pb", "pb3"})
    EXPECT_TRUE(has(EffectKind::kBearingInnerRaceDefect, b)) << b;
  for (const char* s : {"sun_shaft", "ims", "hss"})
    EXPECT_TRUE(has(EffectKind::kShaftUnbalance, s));
  for (const char* s : {"ims", "hss"}) EXPECT_TRUE(has(EffectKind::kShaftMisalignment, s));
  EXPECT_TRUE(has(EffectKind::kPlanetPassModulation, "ring"));
  EXPECT_TRUE(has(EffectKind::kHousingResonance, "b5"));
  EXPECT_TRUE(has(EffectKind::kHousingResonance, "b3"));
  EXPECT_FALSE(has(EffectKind::kHousingResonance, "b4"));  // no sensor there
  EXPECT_FALSE(has(EffectKind::kToothCrack, "planet4"));   // three planets
}

TEST(Effects, ABadEffectIsRefusedNamingTheFieldAndTheRange) {
  model::Drivetrain d = model::paper_2mw();
  std::string error;
  model::Effect e = model::make_effect(EffectKind::kToothCrack, "g9");
  EXPECT_FALSE(model::check_effect(d, e, &error));
  EXPECT_NE(error.find("location"), std::string::npos) << error;
  EXPECT_NE(error.find("g4"), std::string::npos) << error;  // lists what is expected
  e.location = "g4";
  e.set_parameter("stiffness_loss", 1.5);
  EXPECT_FALSE(model::check_effect(d, e, &error));
  EXPECT_NE(error.find("stiffness_loss"), std::string::npos) << error;
  // And the model builder refuses it with the drivetrain's name.
  d.effects.push_back(e);
  EXPECT_FALSE(build_full_model(d, {}, &error));
  EXPECT_NE(error.find("effects"), std::string::npos) << error;
}

// ---- the frequencies each term carries, against drivetrain-2mw.md at 8.33 rpm -------------

TEST(EffectKinematics, OuterRaceDefectOfB5StrikesAtBpfoLessTheSlip) {
  // drivetrain-2mw.md: b5 BPFO = 93.066 Hz; 1 % cage slip → 92.135 Hz.
  const FullModel m =
      model_with({effect(EffectKind::kBearingOuterRaceDefect, "b5", {{"slip", 0.01}})});
  const auto f = effect_forces(m);
  ASSERT_FALSE(f.empty());
  for (const ForceTerm* t : f) EXPECT_NEAR(std::abs(t->order) * kRotorHz, 93.066 * 0.99, 0.01);
}

TEST(EffectKinematics, InnerRaceDefectOfB5StrikesAtBpfiAndPassesTheLoadZoneOncePerHssTurn) {
  // BPFI = 135.785 Hz; the cage slowed by s raises the inner race's pass rate by BPFO·s
  // (BPFI' = Nb·(f_r − FTF(1 − s))); the load zone is met once per hss revolution (14.3032 Hz).
  const double s = 0.01;
  const FullModel m =
      model_with({effect(EffectKind::kBearingInnerRaceDefect, "b5", {{"slip", s}})});
  for (const ForceTerm* t : effect_forces(m)) {
    EXPECT_NEAR(std::abs(t->order) * kRotorHz, 135.785 + 93.066 * s, 0.01);
    ASSERT_EQ(t->modulations.size(), 1u);
    EXPECT_NEAR(std::abs(t->modulations[0].order) * kRotorHz, 14.3032, 1e-3);
  }
}

TEST(EffectKinematics, BallDefectOfB5StrikesAtTwiceTheSpinAndTurnsWithTheCage) {
  // b5: Nb 16, d 28 mm, Dp 150 mm, φ 0: BSF = Dp/2d·(1 − (d/Dp)²)·f_hss = 36.977 Hz,
  // FTF = ½(1 − d/Dp)·f_hss = 5.8168 Hz; both slowed by the slip.
  const double s = 0.01;
  const double bsf = 150.0 / 56.0 * (1.0 - std::pow(28.0 / 150.0, 2)) * 14.3032;
  const double ftf = 0.5 * (1.0 - 28.0 / 150.0) * 14.3032;
  const FullModel m = model_with({effect(EffectKind::kBearingBallDefect, "b5", {{"slip", s}})});
  for (const ForceTerm* t : effect_forces(m)) {
    EXPECT_NEAR(std::abs(t->order) * kRotorHz, 2.0 * bsf * (1.0 - s), 0.01);
    ASSERT_EQ(t->modulations.size(), 1u);
    EXPECT_NEAR(std::abs(t->modulations[0].order) * kRotorHz, ftf * (1.0 - s), 1e-3);
  }
}

TEST(EffectKinematics, OuterRaceDefectsOfB3AndB6StrikeAtTheirBpfo) {
  const FullModel m3 =
      model_with({effect(EffectKind::kBearingOuterRaceDefect, "b3", {{"slip", 0.0}})});
  for (const ForceTerm* t : effect_forces(m3))
    EXPECT_NEAR(std::abs(t->order) * kRotorHz, 26.928, 0.005);
  const FullModel m6 =
      model_with({effect(EffectKind::kBearingOuterRaceDefect, "b6", {{"slip", 0.0}})});
  for (const ForceTerm* t : effect_forces(m6))
    EXPECT_NEAR(std::abs(t->order) * kRotorHz, 81.989, 0.01);
}

TEST(EffectKinematics, CrackedG4ToothWeakensTheHighSpeedMeshOncePerHssTurnForItsContactTime) {
  const FullModel m =
      model_with({effect(EffectKind::kToothCrack, "g4", {{"stiffness_loss", 0.3}})});
  const VaryingStiffness& hs = m.meshes[7];
  ASSERT_EQ(hs.id, "high_speed");
  ASSERT_EQ(hs.modulations.size(), 1u);
  const Modulation& w = hs.modulations[0];
  EXPECT_NEAR(std::abs(w.order) * kRotorHz, 14.3032, 1e-3);
  // Deepest at 1 − loss; weakened over ε_γ/z_g4 of a revolution (ε_γ of the 26/107 pair
  // with m_n 14 mm, β 10°, b 170 mm: between 2 and 3.5).
  const double lowest = *std::min_element(w.table.values.begin(), w.table.values.end());
  EXPECT_NEAR(lowest, 0.7, 0.01);
  int weakened = 0;
  for (double v : w.table.values) weakened += v < 0.9999 ? 1 : 0;
  const double share = static_cast<double>(weakened) / PeriodicTable::kSize;
  EXPECT_GT(share * 26, 2.0);
  EXPECT_LT(share * 26, 3.5);
  // No other mesh is touched.
  for (std::size_t j = 0; j < 7; ++j)
    EXPECT_TRUE(m.meshes[j].modulations.empty()) << m.meshes[j].id;
}

TEST(EffectKinematics, CrackedSunToothMeetsEachPlanetInTurnAtTheSunsSpeedRelativeToTheCarrier) {
  // f_sun − f_carrier = 0.7933 − 0.1388 = 0.6545 Hz; the three planets a third apart.
  const FullModel m = model_with({effect(EffectKind::kToothCrack, "sun")});
  for (int n = 0; n < 3; ++n) {
    ASSERT_EQ(m.meshes[n].modulations.size(), 1u) << m.meshes[n].id;
    EXPECT_NEAR(m.meshes[n].modulations[0].order * kRotorHz, 0.7933 - 0.1388, 1e-3);
  }
  const double p0 = m.meshes[0].modulations[0].phase_cycles;
  for (int n = 1; n < 3; ++n) {
    const double dp = m.meshes[n].modulations[0].phase_cycles - p0;
    EXPECT_NEAR(std::abs(dp - std::round(dp)), 1.0 / 3.0, 1e-9) << "planet " << n + 1;
  }
}

TEST(EffectKinematics, EccentricG1ModulatesTheIntermediateMeshOncePerSunShaftTurn) {
  const FullModel m =
      model_with({effect(EffectKind::kGearEccentricity, "g1", {{"eccentricity_um", 50}})});
  const VaryingStiffness& im = m.meshes[6];
  ASSERT_EQ(im.id, "intermediate");
  // The stage's static transmission error (DynamicsParameters) first, then the run-out.
  ASSERT_EQ(im.excitations.size(), 2u);
  EXPECT_NEAR(im.excitations[0].pattern.order, im.order, 1e-12);
  const MeshExcitation& runout = im.excitations[1];
  EXPECT_NEAR(std::abs(runout.pattern.order) * kRotorHz, 0.7933, 1e-4);
  // The run-out along the line of action: 50 µm times the normal's transverse part cos β_b.
  const double alpha_t = std::atan(std::tan(20 * kPi / 180) / std::cos(10 * kPi / 180));
  const double beta_b = std::atan(std::tan(10 * kPi / 180) * std::cos(alpha_t));
  EXPECT_NEAR(std::abs(runout.amplitude_m), 50e-6 * std::cos(beta_b), 1e-12);
  ASSERT_EQ(im.modulations.size(), 1u);  // the centre-distance change
  EXPECT_NEAR(std::abs(im.modulations[0].order) * kRotorHz, 0.7933, 1e-4);
}

TEST(EffectKinematics, UnbalanceOfTheHssTurnsWithItAtUOmegaSquared) {
  const double u = 0.2;  // [kg·m]
  const FullModel m =
      model_with({effect(EffectKind::kShaftUnbalance, "hss", {{"unbalance_kg_m", u}})});
  const auto f = effect_forces(m);
  ASSERT_EQ(f.size(), 2u);  // x and y, a quarter turn apart
  for (const ForceTerm* t : f) {
    EXPECT_NEAR(t->order * kRotorHz, 14.3032, 1e-3);
    EXPECT_TRUE(t->per_rotor_hz_squared);
    // F = U·(2π f_hss)² = 0.2·(2π·14.3032)² = 1615 N at the paper point.
    EXPECT_NEAR(t->amplitude * kRotorHz * kRotorHz, u * std::pow(2 * kPi * 14.3032, 2), 1.0);
  }
}

TEST(EffectKinematics, MisalignedHssCouplingPushesTwiceAndOncePerTurn) {
  const FullModel m =
      model_with({effect(EffectKind::kShaftMisalignment, "hss", {{"ratio_1x", 0.5}})});
  const auto f = effect_forces(m);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_NEAR(f[0]->order * kRotorHz, 14.3032, 1e-3);
  EXPECT_NEAR(harmonic(f[0]->shape, 2), 0.5, 1e-9);   // ½ of cos 2θ
  EXPECT_NEAR(harmonic(f[0]->shape, 1), 0.25, 1e-9);  // ½ of 0.5·cos θ
  EXPECT_TRUE(f[0]->per_newton_metre);
}

TEST(EffectKinematics, PlanetPassPathRepeatsThreeTimesPerCarrierTurn) {
  // Three equally spaced planets pass each seat at 3·f_carrier = 0.4165 Hz.
  const FullModel m = model_with({effect(EffectKind::kPlanetPassModulation, "ring")});
  ASSERT_EQ(m.paths.size(), 2u);  // one per measured seat
  for (const VaryingStiffness& p : m.paths) {
    EXPECT_NEAR(p.order * kRotorHz, 0.1388, 1e-4);
    EXPECT_GT(harmonic(p.shape, 3), 0.1);
    EXPECT_LT(harmonic(p.shape, 1), 1e-9);
    EXPECT_LT(harmonic(p.shape, 2), 1e-9);
  }
}

TEST(EffectKinematics, HousingResonanceAddsAModeNearItsFrequencyAndTheSensorRidesOnIt) {
  const FullModel healthy = model_with({});
  const FullModel m =
      model_with({effect(EffectKind::kHousingResonance, "b5", {{"frequency_hz", 3000.0}})});
  EXPECT_EQ(m.dofs(), healthy.dofs() + 1);
  const Eigen::VectorXd s = m.mass.cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd k_sym = s.asDiagonal() * m.stiffness * s.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(k_sym);
  double nearest = 1e9;
  for (Eigen::Index i = 0; i < es.eigenvalues().size(); ++i)
    nearest = std::min(nearest, std::abs(std::sqrt(es.eigenvalues()[i]) / (2 * kPi) - 3000.0));
  EXPECT_LT(nearest, 0.05 * 3000.0);  // 20 kg on a 250 kg seat: the coupled mode stays close
  EXPECT_EQ(m.sensors[0].row[m.dof("housing.b5")], 1.0);
}

// ---- the reduced model with any effect switched on -----------------------------------------

TEST(RomEffects, EveryEffectBuildsAndStepsWithoutAllocating) {
  const std::vector<model::Effect> effects = {
      effect(EffectKind::kToothCrack, "g4"),
      effect(EffectKind::kToothCrack, "planet2"),
      effect(EffectKind::kGearEccentricity, "sun"),
      effect(EffectKind::kGearEccentricity, "g1"),
      effect(EffectKind::kBearingOuterRaceDefect, "b5"),
      effect(EffectKind::kBearingInnerRaceDefect, "b1"),
      effect(EffectKind::kBearingBallDefect, "pb"),
      effect(EffectKind::kShaftUnbalance, "sun_shaft"),
      effect(EffectKind::kShaftMisalignment, "ims"),
      effect(EffectKind::kPlanetPassModulation, "ring"),
      effect(EffectKind::kHousingResonance, "b3", {{"frequency_hz", 1500.0}})};
  model::Drivetrain all = model::paper_2mw();
  for (const model::Effect& e : effects) {
    model::Drivetrain d = model::paper_2mw();
    d.effects = {e};
    // All at once but the sun's eccentricity (it modulates the sun meshes, the cracked
    // planet one of them: one modulated gear per mesh) and the housing mode.
    if (e.kind != EffectKind::kHousingResonance && e.location != "sun") all.effects.push_back(e);
    std::string error;
    const auto data = build_rom(d, d.dynamics, RomSettings{}, &error);
    ASSERT_TRUE(data) << model::effect_id(e.kind) << " at " << e.location << ": " << error;
    auto rom = std::make_unique<Rom>(*data);
    rom->reset({14.8, 1.23e6});
    RomOutputs out;
    const long before = g_allocations.load();
    for (int i = 0; i < 500; ++i) rom->step({14.8, 1.23e6}, out);
    EXPECT_EQ(g_allocations.load() - before, 0) << model::effect_id(e.kind);
    EXPECT_TRUE(std::isfinite(out.acceleration_m_s2[0]) && std::isfinite(out.acceleration_m_s2[1]))
        << model::effect_id(e.kind) << " at " << e.location;
  }
  // Nine effects at once fit the ROM's fixed capacity too (two gears' effects on one mesh
  // do not: one modulated gear per mesh, build_rom says so).
  std::string error;
  const auto data = build_rom(all, all.dynamics, RomSettings{}, &error);
  ASSERT_TRUE(data) << error;
  auto rom = std::make_unique<Rom>(*data);
  rom->reset({8.33, 361747.0});
  RomOutputs out;
  const long before = g_allocations.load();
  for (int i = 0; i < 500; ++i) rom->step({8.33, 361747.0}, out);
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_TRUE(std::isfinite(out.acceleration_m_s2[0]));
}

TEST(RomEffects, TwoGearsModulatingOneMeshAreRefusedByName) {
  model::Drivetrain d = model::paper_2mw();
  d.effects = {effect(EffectKind::kToothCrack, "g3"), effect(EffectKind::kToothCrack, "g4")};
  std::string error;
  EXPECT_FALSE(build_rom(d, d.dynamics, RomSettings{}, &error));
  EXPECT_NE(error.find("high_speed"), std::string::npos) << error;
  // The full model takes both.
  EXPECT_TRUE(build_full_model(d, {}, &error)) << error;
}

}  // namespace
