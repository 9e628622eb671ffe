// Long runs (2 s of the full-order model at two operating points, ~10 s natively;
// not repeated under qemu): the reduced model's fidelity against the full model,
// and the kinematics of the simulated spectra against drivetrain-2mw.md.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include "model/drivetrain/description.hpp"
#include "model/drivetrain/kinematics.hpp"
#include "model/dynamics/harmonics.hpp"
#include "model/dynamics/rom.hpp"
#include "model/dynamics/simulate.hpp"

namespace {

using namespace model::dynamics;
constexpr double kRate = 25600.0;

struct Pair {
  SimulationOutputs full, rom;
};

// One full + one ROM run per operating point, shared by the tests of this binary.
const Pair& runs(double rpm, double torque) {
  static std::map<double, Pair> cache;
  auto it = cache.find(rpm);
  if (it != cache.end()) return it->second;
  Pair p;
  std::string error;
  const SimulationSettings s{2.0, kRate, 2, kRomDefaultCutoffHz};
  EXPECT_TRUE(simulate_full(model::paper_2mw(), {rpm, torque}, s, p.full, &error)) << error;
  EXPECT_TRUE(simulate_rom(model::paper_2mw(), {rpm, torque}, s, p.rom, &error)) << error;
  return cache.emplace(rpm, std::move(p)).first->second;
}

void expect_faithful(double rpm, double torque) {
  const Pair& p = runs(rpm, torque);
  const model::Drivetrain d = model::paper_2mw();
  const model::Kinematics k(d);
  for (std::size_t c = 0; c < p.full.acceleration_m_s2.size(); ++c) {
    for (std::size_t stage = 0; stage < 3; ++stage) {
      for (int h = 1; h <= 3; ++h) {
        const double f = h * k.mesh_hz(stage, rpm);
        const double a_full = line_amplitude(p.full.acceleration_m_s2[c], kRate, f);
        const double a_rom = line_amplitude(p.rom.acceleration_m_s2[c], kRate, f);
        EXPECT_NEAR(a_rom / a_full, 1.0, 0.05)
            << p.full.sensor_channels[c] << " stage " << stage << " harmonic " << h << " (" << f
            << " Hz): full " << a_full << ", rom " << a_rom;
      }
    }
  }
  for (std::size_t j = 0; j < p.full.mesh_force_n.size(); ++j) {
    const double r_full = rms_about_mean(p.full.mesh_force_n[j]);
    const double r_rom = rms_about_mean(p.rom.mesh_force_n[j]);
    EXPECT_NEAR(r_rom / r_full, 1.0, 0.05) << p.full.mesh_ids[j];
  }
}

TEST(RomFidelity, MeshHarmonicsAndMeshForcesAgreeWithTheFullModelAtThePaperPoint) {
  expect_faithful(8.33, 361747.0);
}

TEST(RomFidelity, MeshHarmonicsAndMeshForcesAgreeWithTheFullModelAtRated) {
  expect_faithful(14.8, 1.23e6);
}

TEST(CarrierFrame, CoriolisAndCentripetalTermsMoveTheSensorsMeshLinesByLessThanAPercent) {
  // The reduced model leaves out the turning frame's inertia terms (rom.hpp): 2Ω ≤ 3.1 rad/s
  // and Ω² ≤ 2.4 s⁻² at rated against ω ≥ 300 rad/s of the translational modes they couple,
  // so they should move the sensors' mesh lines by well under 1 %. Measured at rated (the
  // largest Ω) on the full model with and without them.
  const SimulationSettings with{2.0, kRate, 2, kRomDefaultCutoffHz};
  SimulationSettings without = with;
  without.structure.frame_inertia = false;
  SimulationOutputs a, b;
  std::string error;
  ASSERT_TRUE(simulate_full(model::paper_2mw(), {14.8, 1.23e6}, with, a, &error)) << error;
  ASSERT_TRUE(simulate_full(model::paper_2mw(), {14.8, 1.23e6}, without, b, &error)) << error;
  const model::Kinematics k(model::paper_2mw());
  double worst = 0.0;
  for (std::size_t c = 0; c < a.acceleration_m_s2.size(); ++c) {
    for (std::size_t stage = 0; stage < 3; ++stage) {
      for (int h = 1; h <= 3; ++h) {
        const double f = h * k.mesh_hz(stage, 14.8);
        const double ratio = line_amplitude(b.acceleration_m_s2[c], kRate, f) /
                             line_amplitude(a.acceleration_m_s2[c], kRate, f);
        worst = std::max(worst, std::abs(ratio - 1.0));
      }
    }
  }
  RecordProperty("worst_relative_change", std::to_string(worst));
  EXPECT_LT(worst, 0.01);
}

// Amplitude spectrum on a 0.5 Hz grid (the Hann main lobe of a 2 s record is ±1 Hz).
struct Spectrum {
  std::vector<double> hz, amp;
  double median() const {
    std::vector<double> a = amp;
    std::nth_element(a.begin(), a.begin() + a.size() / 2, a.end());
    return a[a.size() / 2];
  }
  double strongest_hz() const { return hz[std::max_element(amp.begin(), amp.end()) - amp.begin()]; }
};
Spectrum spectrum(const std::vector<double>& x, double lo, double hi) {
  Spectrum s;
  for (double f = lo; f <= hi; f += 0.5) {
    s.hz.push_back(f);
    s.amp.push_back(line_amplitude(x, kRate, f));
  }
  return s;
}

TEST(SpectrumKinematics, Point1IsDominatedByTheHighSpeedMeshAndItsHarmonicsAtThePaperPoint) {
  // Arrange: hss mesh at 8.33 rpm = 371.884 Hz (drivetrain-2mw.md).
  const Pair& p = runs(8.33, 361747.0);
  const std::vector<double>& point1 = p.full.acceleration_m_s2[0];
  // Act
  const Spectrum s = spectrum(point1, 20.0, 3000.0);
  // Assert: the strongest line is an hss-mesh harmonic; 1×, 2×, 3× stand ≥ 10× above
  // the spectrum's median level.
  const double k = s.strongest_hz() / 371.884;
  EXPECT_NEAR(k, std::round(k), 1.0 / 371.884) << "strongest line " << s.strongest_hz() << " Hz";
  for (int h = 1; h <= 3; ++h) {
    EXPECT_GT(line_amplitude(point1, kRate, h * 371.884), 10.0 * s.median()) << h << "× hss mesh";
  }
}

TEST(SpectrumKinematics, IntermediateMeshIsClearlyPresentAtPoint2) {
  const Pair& p = runs(8.33, 361747.0);
  const std::vector<double>& point2 = p.full.acceleration_m_s2[1];
  const Spectrum s = spectrum(point2, 20.0, 3000.0);
  EXPECT_GT(line_amplitude(point2, kRate, 72.987), 10.0 * s.median());
}

TEST(SpectrumKinematics, PlanetaryMeshAndItsHarmonicsDominateTheSunPlanetMeshForce) {
  // Planetary mesh at 8.33 rpm = 13.745 Hz; its 5th harmonic (68.7 Hz) lies near the
  // first planetary modes (77–93 Hz) and may be the strongest line.
  const Pair& p = runs(8.33, 361747.0);
  const std::vector<double>& f = p.full.mesh_force_n[0];  // sun_planet_1
  const Spectrum s = spectrum(f, 5.0, 100.0);
  const double k = s.strongest_hz() / 13.745;
  EXPECT_NEAR(k, std::round(k), 0.5 / 13.745) << "strongest line " << s.strongest_hz() << " Hz";
  EXPECT_GT(line_amplitude(f, kRate, 13.745), 10.0 * s.median());
}

}  // namespace
