// Long runs (2 s of the full-order model at two operating points, ~10 s natively;
// not repeated under qemu): the reduced model's fidelity against the full model,
// and the kinematics of the simulated spectra against drivetrain-2mw.md.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "frequency_response.hpp"
#include "model/drivetrain/description.hpp"
#include "model/drivetrain/kinematics.hpp"
#include "model/dynamics/harmonics.hpp"
#include "model/dynamics/newmark.hpp"
#include "model/dynamics/rom.hpp"
#include "model/dynamics/simulate.hpp"
#include "paper_models.hpp"

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
  // 4 Newmark substeps per sample: the housing mode near 1.8 kHz makes the third rated hss
  // harmonic (1982 Hz) sensitive to Newmark's period error (ωΔt)²/12 — with 2 substeps the
  // full model's point2 line there is 6 % below its converged value (4 and 6 substeps agree
  // within 1 %), which is the reference's error, not the ROM's.
  const SimulationSettings s{2.0, kRate, 4, kRomDefaultCutoffHz};
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
  // first planetary modes (77–93 Hz) and may be the strongest line. The sun shaft also
  // carries g1, whose mesh (72.987 Hz) is excited by its own transmission error and
  // reaches the sun–planet force through the shaft's torsion: the strongest line is a
  // harmonic of one of the sun shaft's two meshes, and without the intermediate stage's
  // transmission error (a ROM run, same kinematics) one of the planetary mesh.
  const Pair& p = runs(8.33, 361747.0);
  const std::vector<double>& f = p.full.mesh_force_n[0];  // sun_planet_1
  const Spectrum s = spectrum(f, 5.0, 100.0);
  const double k = s.strongest_hz() / 13.745;
  const bool planetary = std::abs(k - std::round(k)) < 0.5 / 13.745;
  const bool intermediate = std::abs(s.strongest_hz() - 72.987) < 0.5;
  EXPECT_TRUE(planetary || intermediate) << "strongest line " << s.strongest_hz() << " Hz";
  EXPECT_GT(line_amplitude(f, kRate, 13.745), 10.0 * s.median());

  model::Drivetrain d = model::paper_2mw();
  for (std::size_t h = 0; h < model::kTransmissionErrorHarmonics; ++h)
    d.dynamics.transmission_error_m[model::kTransmissionErrorHarmonics + h] = 0.0;
  SimulationOutputs rom;
  std::string error;
  ASSERT_TRUE(simulate_rom(d, {8.33, 361747.0}, {2.0, kRate, 2, kRomDefaultCutoffHz}, rom, &error))
      << error;
  const Spectrum s0 = spectrum(rom.mesh_force_n[0], 5.0, 100.0);
  const double k0 = s0.strongest_hz() / 13.745;
  EXPECT_NEAR(k0, std::round(k0), 0.5 / 13.745) << "strongest line " << s0.strongest_hz() << " Hz";
}

TEST(FullModelExcitation, TransmissionErrorDrivesTheSensorsAsTheFrequencyResponsePredicts) {
  // As the ROM's test (test_rom.cpp) for the full model's Newmark integrator: constant
  // stiffness, one harmonic of the hss mesh's transmission error, steady state against the
  // frequency response (K̄ − ω²M + iωC)⁻¹. Newmark's period error at 372 Hz with 2 substeps
  // is 1e-4: tolerance 1 %.
  model::Drivetrain d = model::paper_2mw();
  d.dynamics.transmission_error_m.fill(0.0);
  d.dynamics.transmission_error_m[2 * model::kTransmissionErrorHarmonics] = 2e-6;
  d.dynamics.bearing_stiffness_fluctuation = 0.0;
  d.dynamics.bearing_compliance_scale = 0.0;
  std::string error;
  auto m = build_full_model(d, {}, &error);
  ASSERT_TRUE(m) << error;
  for (auto& v : m->meshes) v.shape = PeriodicTable::constant(1.0);
  NewmarkIntegrator integ(*m, 1.0 / (2 * kRate));
  integ.reset_static({8.33, 0.0});
  std::vector<double> p1;
  std::vector<double> p2;
  for (int i = 0; i < 25600; ++i) {
    integ.step();
    integ.step();
    if (i >= 12800) {
      p1.push_back(integ.sensor_m_s2(0));
      p2.push_back(integ.sensor_m_s2(1));
    }
  }
  const VaryingStiffness& hss = m->meshes[7];
  ASSERT_EQ(hss.id, "high_speed");
  const double f = hss.order * 8.33 / 60.0;
  for (int s = 0; s < 2; ++s) {
    const double expect =
        frequency_response::sensor_response(*m, hss.directions.col(0), hss.mean_n_m * 2e-6, f, s);
    const double got = line_amplitude(s == 0 ? p1 : p2, kRate, f);
    EXPECT_NEAR(got / expect, 1.0, 0.01) << "sensor " << s << ": " << got << " vs " << expect;
  }
}

TEST(SeatParticipation,
     AnUnmeasuredSeatsPathReachesTheSensorsAlikeInTheFullModelTheRomAndTheFrequencyResponse) {
  // b4 (intermediate shaft, no sensor) with participation 0.5 in point1's mode 1: the
  // intermediate mesh's transmission error (1×, constant stiffness: time-invariant) now also
  // reaches point1 through b4's seat. Newmark (2 substeps) and the ROM (modal truncation +
  // static correction of b4's direction, which now has the housing term) must both give the
  // steady-state tone the frequency response (K̄ − ω²M + iωC)⁻¹ of the full model gives,
  // within 2 % (at this 73 Hz tone, 0.5 s after a 0.5 s settle, both integrators read 1–1.4 %
  // off the frequency response with or without the path, alike to 0.05 %: the slow modes'
  // transient, not the path), agree with each other within 0.5 %, and the path must matter:
  // point1's tone differs from the model without it by more than 20 %.
  const std::size_t modes = model::kHousingPoints * model::kHousingModesPerPoint;
  model::Drivetrain d = model::paper_2mw();
  d.dynamics.transmission_error_m.fill(0.0);
  d.dynamics.transmission_error_m[1 * model::kTransmissionErrorHarmonics] = 2e-6;  // ims, 1×
  d.dynamics.bearing_stiffness_fluctuation = 0.0;
  d.dynamics.bearing_compliance_scale = 0.0;
  model::Drivetrain d0 = d;
  d.dynamics.housing_seat_participation[(3 - model::kHousingSeatFirstBearing) * modes] = 0.5;
  std::string error;
  auto m = build_full_model(d, {}, &error);
  ASSERT_TRUE(m) << error;
  auto m0 = build_full_model(d0, {}, &error);
  ASSERT_TRUE(m0) << error;
  for (auto& v : m->meshes) v.shape = PeriodicTable::constant(1.0);
  for (auto& v : m0->meshes) v.shape = PeriodicTable::constant(1.0);
  const VaryingStiffness& ims = m->meshes[6];
  ASSERT_EQ(ims.id, "intermediate");
  const double rpm = 8.33;
  const double f = ims.order * rpm / 60.0;
  const double force = ims.mean_n_m * 2e-6;

  NewmarkIntegrator integ(*m, 1.0 / (2 * kRate));
  integ.reset_static({rpm, 0.0});
  const auto data = build_rom(*m, 1.0 / kRate, kRomDefaultCutoffHz);
  ASSERT_TRUE(data);
  Rom rom(*data);
  const RomInputs in{rpm, 0.0};
  rom.reset(in);
  RomOutputs out;
  std::vector<double> full[2], reduced[2];
  for (int i = 0; i < 25600; ++i) {
    integ.step();
    integ.step();
    rom.step(in, out);
    if (i >= 12800) {
      for (int s = 0; s < 2; ++s) {
        full[s].push_back(integ.sensor_m_s2(s));
        reduced[s].push_back(out.acceleration_m_s2[static_cast<std::size_t>(s)]);
      }
    }
  }
  for (int s = 0; s < 2; ++s) {
    const double expect =
        frequency_response::sensor_response(*m, ims.directions.col(0), force, f, s);
    const double a_full = line_amplitude(full[s], kRate, f);
    const double a_rom = line_amplitude(reduced[s], kRate, f);
    EXPECT_NEAR(a_full / expect, 1.0, 0.02) << "sensor " << s;
    EXPECT_NEAR(a_rom / expect, 1.0, 0.02) << "sensor " << s;
    EXPECT_NEAR(a_rom / a_full, 1.0, 0.005) << "sensor " << s;
  }
  const double with = frequency_response::sensor_response(*m, ims.directions.col(0), force, f, 0);
  const double without =
      frequency_response::sensor_response(*m0, m0->meshes[6].directions.col(0), force, f, 0);
  EXPECT_GT(std::abs(with / without - 1.0), 0.2) << with << " vs " << without;
}

}  // namespace

namespace {

using test_support::paper_with_body;

// Frequency in [lo, hi] where the sensor's displacement |a|/ω² per unit force along
// `pattern` peaks, on a log grid of step 1 + `step`.
double displacement_peak_hz(const FullModel& m, const Eigen::VectorXd& pattern, int sensor,
                            double lo, double hi, double step) {
  double best = 0.0, f_best = lo;
  for (double f = lo; f <= hi; f *= 1.0 + step) {
    const double w = 2.0 * std::numbers::pi * f;
    const double x = frequency_response::sensor_response(m, pattern, 1.0, f, sensor) / (w * w);
    if (x > best) best = x, f_best = f;
  }
  return f_best;
}

}  // namespace

TEST(GearboxBody, AHeavyBodysModeIsTheHandValueSqrtKOverM) {
  // A box far heavier than what it carries (1e6 kg against the parallel stages' ~1e3 kg of
  // shafts and gears) on mounts far stiffer than its bearings (K = M(2π·150 Hz)² = 8.9e11 N/m
  // against Σ k_b3..b6 = 5.4e9: ≤ 0.6 % of the stiffness): a rigid body on a spring, whose
  // mode (1/2π)√(K/M) must be the peak of the transfer from a force on the box to point1's
  // sensor within 1 % — the hand value, not the model's eigen-solution. (Point2's reading
  // peaks at 134 Hz instead: at b3 the box's motion also rings the intermediate shaft on its
  // bearings, a mode of the gearbox, not of the box.)
  const double f0 = 150.0, mass = 1.0e6;
  const double k = mass * std::pow(2.0 * std::numbers::pi * f0, 2);
  std::string error;
  auto m = build_full_model(paper_with_body(mass, k, 0.05), {}, &error);
  ASSERT_TRUE(m) << error;
  Eigen::VectorXd on_body = Eigen::VectorXd::Zero(m->dofs());
  on_body[m->dof("gearbox_body")] = 1.0;
  EXPECT_NEAR(displacement_peak_hz(*m, on_body, 0, 0.8 * f0, 1.25 * f0, 1e-3) / f0, 1.0, 0.01);
}

TEST(GearboxBody, TheRomKeepsTheBodysPathFromTheMeshesToBothSensors) {
  // At the engineering prior (5 t on 1e9 N/m, calibration_space.hpp) the body carries the
  // parallel stages with it: its mode seen from a force on the box sits below the 71 Hz of
  // the body alone. The intermediate mesh's transmission error (1×, constant stiffness: a
  // time-invariant model) at the speed that puts its tone on that mode: the ROM (the mode
  // below its cut-off, kept exactly: one more retained mode, the step the same size) gives the
  // steady-state tone of the frequency response
  // (K̄ − ω²M + iωC)⁻¹ within 2 % at both sensors, and the body matters there: point1's tone
  // differs from the model without it by more than 50 %.
  model::Drivetrain d = paper_with_body(5000.0, 1.0e9, 0.08);
  d.dynamics.transmission_error_m.fill(0.0);
  d.dynamics.transmission_error_m[1 * model::kTransmissionErrorHarmonics] = 2e-6;  // ims, 1×
  d.dynamics.bearing_stiffness_fluctuation = 0.0;
  d.dynamics.bearing_compliance_scale = 0.0;
  model::Drivetrain d0 = d;
  d0.dynamics.gearbox_body_mass_kg = 0.0;
  std::string error;
  auto m = build_full_model(d, {}, &error);
  ASSERT_TRUE(m) << error;
  auto m0 = build_full_model(d0, {}, &error);
  ASSERT_TRUE(m0) << error;
  for (auto& v : m->meshes) v.shape = PeriodicTable::constant(1.0);
  for (auto& v : m0->meshes) v.shape = PeriodicTable::constant(1.0);
  Eigen::VectorXd on_body = Eigen::VectorXd::Zero(m->dofs());
  on_body[m->dof("gearbox_body")] = 1.0;
  const double f = displacement_peak_hz(*m, on_body, 0, 20.0, 120.0, 2e-3);
  EXPECT_LT(f, 71.2);  // the body alone: 71.2 Hz; it carries more than its own mass
  const VaryingStiffness& ims = m->meshes[6];
  ASSERT_EQ(ims.id, "intermediate");
  const double rpm = 60.0 * f / ims.order;
  const double force = ims.mean_n_m * 2e-6;
  const auto data = build_rom(*m, 1.0 / kRate, kRomDefaultCutoffHz);
  ASSERT_TRUE(data);
  const auto data0 = build_rom(*m0, 1.0 / kRate, kRomDefaultCutoffHz);
  ASSERT_TRUE(data0);
  // One more retained mode, the same correction vectors, the step's size unchanged.
  EXPECT_EQ(data->eigenmodes, data0->eigenmodes + 1);
  EXPECT_EQ(data->correction_vectors, data0->correction_vectors);
  EXPECT_EQ(data->dofs, data0->dofs);
  Rom rom(*data);
  const RomInputs in{rpm, 0.0};
  rom.reset(in);
  RomOutputs out;
  std::vector<double> reduced[2];
  for (int i = 0; i < 3 * 25600; ++i) {  // 2 s settle (ξ = 0.08 at ~50 Hz: τ = 40 ms), 1 s read
    rom.step(in, out);
    if (i >= 2 * 25600) {
      for (int s = 0; s < 2; ++s)
        reduced[s].push_back(out.acceleration_m_s2[static_cast<std::size_t>(s)]);
    }
  }
  for (int s = 0; s < 2; ++s) {
    const double expect =
        frequency_response::sensor_response(*m, ims.directions.col(0), force, f, s);
    EXPECT_NEAR(line_amplitude(reduced[s], kRate, f) / expect, 1.0, 0.02) << "sensor " << s;
  }
  const double with = frequency_response::sensor_response(*m, ims.directions.col(0), force, f, 0);
  const double without =
      frequency_response::sensor_response(*m0, m0->meshes[6].directions.col(0), force, f, 0);
  EXPECT_GT(std::abs(with / without - 1.0), 0.5) << with << " vs " << without;
}
