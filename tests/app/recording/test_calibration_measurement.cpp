// A bundle measured for calibration (app/recording/calibration_measurement.hpp), the one
// measurement `drivetwin calibrate` and calibration_bench --bundle calibrate against: on a
// bundle synthesised here from the reference drivetrain's kinematics (drivetrain-2mw.md:
// hss mesh = 26 · f_hss, intermediate mesh = 21 · f_ims, f_ims = f_hss · 26/107) as pure
// sines of known amplitude plus a once-per-hss-revolution tacho, the averaged tones, RMS and
// order spectrum must be the sines' own (Parseval, the Hann window's amplitude correction),
// the windows as many as the tacho's pulses hold, and a missing channel is named.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <random>
#include <string>

#include "hal/recording_bundle.hpp"
#include "model/calibration/calibrator.hpp"
#include "model/calibration/lumped_simulator.hpp"
#include "model/drivetrain/description.hpp"
#include "recording/calibration_measurement.hpp"

// A named namespace: the test files of this binary are compiled as one translation unit.
namespace calibration_measurement_test {

namespace fs = std::filesystem;
namespace mc = model::calibration;

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kRpm = 8.33;
constexpr double kRatio = (1.0 + 99.0 / 21.0) * (92.0 / 21.0) * (107.0 / 26.0);  // hss/rotor
constexpr double kImsMeshOrder = 21.0 * 26.0 / 107.0;  // intermediate mesh / hss speed
constexpr double kRate = 25600.0;
constexpr double kNoise = 0.02;  // [m/s²] rms, white

// point1: hss mesh 1× 1.0, 2× 0.4, intermediate mesh 1× 0.3 m/s²; point2: hss mesh 1× 0.5,
// intermediate mesh 1× 0.6, 2× 0.2 m/s²; 5.5 s (78 hss revolutions).
hal::Recording synthesize(bool with_point2) {
  const double f_hss = kRpm / 60.0 * kRatio;
  const auto n = static_cast<std::size_t>(5.5 * kRate);
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, kNoise);
  hal::Recording rec;
  rec.sample_rate_hz = kRate;
  rec.channels = {{"point1", "b5", "radial", "", "m/s^2"},
                  {"tacho", "hss", "", "once_per_rev", "V"}};
  if (with_point2) rec.channels.push_back({"point2", "b3", "radial", "", "m/s^2"});
  rec.samples.assign(rec.channels.size(), std::vector<double>(n));
  for (std::size_t i = 0; i < n; ++i) {
    const double rev = f_hss * static_cast<double>(i) / kRate;  // hss revolutions
    rec.samples[0][i] = 1.0 * std::sin(kTwoPi * 26.0 * rev) +
                        0.4 * std::sin(kTwoPi * 52.0 * rev + 0.3) +
                        0.3 * std::sin(kTwoPi * kImsMeshOrder * rev + 1.0) + noise(rng);
    const double frac = rev + 0.5 - std::floor(rev + 0.5);
    rec.samples[1][i] = frac < 0.02 ? 5.0 : 0.0;
    if (with_point2) {
      rec.samples[2][i] = 0.5 * std::sin(kTwoPi * 26.0 * rev + 2.0) +
                          0.6 * std::sin(kTwoPi * kImsMeshOrder * rev) +
                          0.2 * std::sin(kTwoPi * 2.0 * kImsMeshOrder * rev + 0.7) + noise(rng);
    }
  }
  rec.operating_point.rotor_speed_rpm = kRpm;
  rec.operating_point.input_torque_nm = 361747.0;
  return rec;
}

fs::path write(const std::string& name, const hal::Recording& rec) {
  const fs::path dir = fs::temp_directory_path() /
                       ("drivetwin-test-calibration-measurement-" + std::to_string(::getpid())) /
                       name;
  fs::remove_all(dir);
  const auto err = hal::write_bundle(dir, rec);
  EXPECT_FALSE(err) << err->to_string();
  return dir;
}

// The calibrator's feature configuration (mesh and shaft orders from paper-2mw) at 32
// revolutions × 256 samples per revolution, as calibrate builds its extractor.
struct Extractor {
  model::Drivetrain d = model::paper_2mw();
  mc::LumpedSimulator sim{d, mc::LumpedSimulatorConfig{}};
  mc::Calibrator cal{sim, d,
                     [] {
                       model::dsp::FeatureConfig fc;
                       fc.revolutions = 32;
                       fc.samples_per_rev = 256;
                       return fc;
                     }(),
                     mc::CalibratorConfig{}};
  model::dsp::FeatureExtractor fx{cal.feature_config()};
};

TEST(CalibrationMeasurement, TonesRmsAndSpectrumAreTheSinesOwnAveragedOverTheTachosWindows) {
  // Arrange
  const fs::path dir = write("good", synthesize(true));
  Extractor e;
  // Act: up to 4 windows of 32 revolutions asked; 78 revolutions hold 2 (a window needs its
  // 33 pulses from its first).
  const app::recording::CalibrationMeasurement m =
      app::recording::measure_for_calibration(dir, 4, e.fx, "");
  // Assert
  EXPECT_EQ(m.windows, 2u);
  EXPECT_EQ(m.speed_source.find("tacho") != std::string::npos, true) << m.speed_source;
  EXPECT_NEAR(m.measured.op.rotor_speed_rpm, kRpm, 0.002 * kRpm);
  EXPECT_DOUBLE_EQ(m.measured.op.input_torque_nm, 361747.0);
  // Tones: index mesh · harmonics + (h − 1), meshes planetary, intermediate, high-speed.
  const model::dsp::PointFeatures& p1 = m.measured.measured[0];
  const model::dsp::PointFeatures& p2 = m.measured.measured[1];
  EXPECT_NEAR(p1.amplitude[2 * 3 + 0], 1.0, 0.02);
  EXPECT_NEAR(p1.amplitude[2 * 3 + 1], 0.4, 0.02 * 0.4);
  EXPECT_NEAR(p1.amplitude[1 * 3 + 0], 0.3, 0.02 * 0.3);
  EXPECT_NEAR(p2.amplitude[2 * 3 + 0], 0.5, 0.02 * 0.5);
  EXPECT_NEAR(p2.amplitude[1 * 3 + 0], 0.6, 0.02 * 0.6);
  EXPECT_NEAR(p2.amplitude[1 * 3 + 1], 0.2, 0.02 * 0.2);
  EXPECT_TRUE(p1.resolved[2 * 3 + 0] && p1.resolved[2 * 3 + 1] && p1.resolved[1 * 3 + 0]);
  // RMS (Parseval): √(Σ A²/2 + σ²).
  EXPECT_NEAR(p1.rms, std::sqrt((1.0 + 0.16 + 0.09) / 2.0 + kNoise * kNoise), 0.01 * 0.79);
  EXPECT_NEAR(p2.rms, std::sqrt((0.25 + 0.36 + 0.04) / 2.0 + kNoise * kNoise), 0.01 * 0.57);
  // Order spectrum: line k at order k/32; the hss mesh 1× (order 26) on line 832.
  ASSERT_EQ(m.spectrum[0].size(), 256u * 32u / 2u + 1u);
  EXPECT_NEAR(m.spectrum[0][26 * 32], 1.0, 0.02);
  EXPECT_NEAR(m.spectrum[1][26 * 32], 0.5, 0.02 * 0.5);
  EXPECT_LT(m.spectrum[0][20 * 32], 0.01);  // no line at order 20
  fs::remove_all(dir.parent_path());
}

TEST(CalibrationMeasurement, AMissingMeasurementPointChannelIsNamed) {
  // Arrange
  const fs::path dir = write("no-point2", synthesize(false));
  Extractor e;
  // Act
  std::string message;
  try {
    (void)app::recording::measure_for_calibration(dir, 4, e.fx, "");
  } catch (const app::recording::BundleCheckError& err) {
    message = err.what();
  }
  // Assert: the file, the channel and where the measurement point is.
  EXPECT_NE(message.find("recording.json"), std::string::npos) << message;
  EXPECT_NE(message.find("'point2'"), std::string::npos) << message;
  EXPECT_NE(message.find("b3"), std::string::npos) << message;
  fs::remove_all(dir.parent_path());
}

}  // namespace calibration_measurement_test
