// RomEffectSimulator remembers its last simulations: a call with the inputs of one of them
// returns that call's waveforms without simulating again. The expectation is independent of
// the memory: a second simulator that has never seen the inputs simulates them afresh, and
// the answers must agree bit for bit; inputs that differ in one parameter (or in the effect's
// severity) must be simulated, not answered from memory.
#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "model/calibration/lumped_simulator.hpp"
#include "model/diagnosis/effect_model.hpp"
#include "model/diagnosis/signatures.hpp"
#include "model/drivetrain/description.hpp"

namespace effect_model_test {
namespace md = model::diagnosis;
namespace mc = model::calibration;

constexpr double kSettle = 0.01;   // [s]
constexpr double kRate = 4096.0;   // [Hz]
constexpr double kSeconds = 0.05;  // [s]
const mc::OperatingPoint kOp{8.33, 361747.0};

using Waves = std::array<std::vector<double>, mc::kMeasurementPoints>;

Waves run(md::RomEffectSimulator& sim, const model::DynamicsParameters& p,
          const std::vector<md::EffectSetting>& fx = {}) {
  std::array<mc::WaveformView, mc::kMeasurementPoints> w{};
  EXPECT_TRUE(sim.simulate(p, fx, kOp, kRate, kSeconds, w)) << sim.error();
  Waves out;
  for (std::size_t i = 0; i < w.size(); ++i) out[i].assign(w[i].samples, w[i].samples + w[i].count);
  return out;
}

TEST(RomEffectSimulator, ARepeatedCallReturnsWhatAFreshSimulationGivesWithoutSimulating) {
  const model::Drivetrain d = model::paper_2mw();
  const model::DynamicsParameters a = mc::with_nominal_damping(d.dynamics);
  model::DynamicsParameters b = a;
  b.mesh_stiffness_scale[2] *= 1.05;

  md::RomEffectSimulator sim(d, kSettle);
  const Waves first_a = run(sim, a);
  const Waves first_b = run(sim, b);
  EXPECT_EQ(sim.repeats(), 0u);
  EXPECT_NE(first_a[0], first_b[0]);  // a different model: simulated, not remembered

  const Waves again_a = run(sim, a);
  EXPECT_EQ(sim.repeats(), 1u);
  md::RomEffectSimulator fresh(d, kSettle);
  const Waves fresh_a = run(fresh, a);
  EXPECT_EQ(fresh.repeats(), 0u);
  for (std::size_t p = 0; p < mc::kMeasurementPoints; ++p) {
    ASSERT_EQ(fresh_a[p].size(), static_cast<std::size_t>(kSeconds * kRate) + 1);
    EXPECT_EQ(again_a[p], fresh_a[p]) << "point " << p;
    EXPECT_EQ(first_a[p], fresh_a[p]) << "point " << p;
  }

  // kRemembered other models later, a is forgotten: simulated again, to the same waveforms.
  for (std::size_t i = 0; i < md::RomEffectSimulator::kRemembered; ++i) {
    model::DynamicsParameters c = a;
    c.rayleigh_zeta *= 1.0 + 0.01 * static_cast<double>(i + 1);
    run(sim, c);
  }
  EXPECT_EQ(sim.repeats(), 1u);
  EXPECT_EQ(run(sim, a), fresh_a);
  EXPECT_EQ(sim.repeats(), 1u);
}

TEST(RomEffectSimulator, AnEffectOfAnotherSeverityIsSimulatedAgain) {
  const model::Drivetrain d = model::paper_2mw();
  const md::Catalogue cat = md::build_catalogue(d, {"b5", "b3"});
  const md::Hypothesis* crack = nullptr;
  for (const md::Hypothesis& h : cat.hypotheses)
    if (h.effect == md::Effect::kToothCrack && h.location == "g4") crack = &h;
  ASSERT_NE(crack, nullptr);
  const model::DynamicsParameters p = mc::with_nominal_damping(d.dynamics);
  md::RomEffectSimulator sim(d, kSettle);
  md::EffectSetting s;
  s.hypothesis = crack;
  s.values = {0.2, 0.0, 0.0, 0.0};
  const Waves w02 = run(sim, p, {s});
  s.values[0] = 0.3;
  const Waves w03 = run(sim, p, {s});
  EXPECT_EQ(sim.repeats(), 0u);
  EXPECT_NE(w02[0], w03[0]);
  s.values[0] = 0.2;
  EXPECT_EQ(run(sim, p, {s}), w02);
  EXPECT_EQ(sim.repeats(), 1u);
}

}  // namespace effect_model_test
