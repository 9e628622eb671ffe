// The shared speed reference: which evidence wins, and the mesh line recovered from a
// synthetic signal whose shaft speed is known.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "model/drivetrain/description.hpp"
#include "model/drivetrain/kinematics.hpp"
#include "signal/speed_reference.hpp"

namespace {

using app::signal::SpeedEvidence;

TEST(SpeedReference, EnoughPulsesWinAndGiveTheirMeanSpeed) {
  const model::Drivetrain d = model::paper_2mw();
  const model::Kinematics k(d);
  SpeedEvidence e;
  for (int i = 0; i <= 20; ++i) e.hss_pulses_s.push_back(0.05 * i);  // 20 Hz
  e.min_pulses = 21;
  e.scada_rotor_rpm = 10.0;
  const auto r = app::signal::choose_speed_reference(e, k);
  EXPECT_EQ(r.source, "tacho");
  EXPECT_NEAR(r.mean_hss_hz(), 20.0, 1e-12);
}

TEST(SpeedReference, TooFewPulsesFallBackToScadaTimesTheGearRatio) {
  const model::Drivetrain d = model::paper_2mw();
  const model::Kinematics k(d);
  SpeedEvidence e;
  e.hss_pulses_s = {0.0, 0.05};
  e.min_pulses = 21;
  e.scada_rotor_rpm = 12.0;
  const auto r = app::signal::choose_speed_reference(e, k);
  EXPECT_EQ(r.source, "scada");
  EXPECT_NEAR(r.mean_hss_hz(), 12.0 / 60.0 * k.overall_ratio(), 1e-12);
}

TEST(SpeedReference, WithoutPulsesOrScadaTheMeshLineRefinesTheNominalSpeed) {
  // Arrange: the hss mesh tone of a shaft 2 % faster than the operating point says.
  const model::Drivetrain d = model::paper_2mw();
  const model::Kinematics k(d);
  const double nominal_rpm = 14.0;
  const double true_rpm = nominal_rpm * 1.02;
  const double mesh_hz = k.mesh_hz(k.stage_count() - 1, true_rpm);
  const double fs = 25600.0;
  std::vector<double> x(static_cast<std::size_t>(fs * 4.0));
  for (std::size_t i = 0; i < x.size(); ++i) {
    x[i] = std::sin(2.0 * std::numbers::pi * mesh_hz * static_cast<double>(i) / fs);
  }
  SpeedEvidence e;
  e.point1 = x.data();
  e.samples = x.size();
  e.sample_rate_hz = fs;
  e.nominal_rotor_rpm = nominal_rpm;
  // Act
  const auto r = app::signal::choose_speed_reference(e, k);
  // Assert: within a fraction of the FFT's line spacing (25600/65536 Hz at the mesh).
  EXPECT_EQ(r.source, "mesh line");
  const double true_hss_hz = true_rpm / 60.0 * k.overall_ratio();
  const double line_in_hss_hz = fs / 65536.0 * true_hss_hz / mesh_hz;
  EXPECT_NEAR(r.hss_hz, true_hss_hz, line_in_hss_hz);
}

TEST(SpeedReference, NothingElseLeavesTheOperatingPoint) {
  const model::Drivetrain d = model::paper_2mw();
  const model::Kinematics k(d);
  SpeedEvidence e;
  e.nominal_rotor_rpm = 8.33;
  const auto r = app::signal::choose_speed_reference(e, k);
  EXPECT_EQ(r.source, "operating point");
  EXPECT_NEAR(r.hss_hz, 8.33 / 60.0 * k.overall_ratio(), 1e-12);
}

}  // namespace
