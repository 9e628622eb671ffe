// The bundle validation layer (app/recording/bundle_check.hpp) against the contract
// (shared/reference/recording-bundle.md) and the physics that ties metadata to signal:
// bundles are synthesised here from the reference drivetrain's kinematics (tooth counts
// of drivetrain-2mw.md: hss mesh = 26 · f_hss, intermediate mesh = 21 · f_ims) as sines
// in noise plus a once-per-hss-revolution tacho, then written with hal::write_bundle
// and tampered with the way the issue found them (a wrong speed in the metadata, a
// sample rate declared wrong, a torque or speed out of range, only a wind speed, a
// channel in g). Every refusal names the file and field; a good bundle passes with its
// speeds agreeing.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <string>

#include "hal/recording_bundle.hpp"
#include "recording/bundle_check.hpp"
#include "support/run_command.hpp"

namespace {

namespace fs = std::filesystem;
using app::recording::BundleCheckError;
using app::recording::load_bundle;

constexpr double kPi = std::numbers::pi;
constexpr double kRpm = 8.33;  // paper check point
// Reference drivetrain (drivetrain-2mw.md): hss = rotor × (1 + 99/21) × 92/21 × 107/26.
constexpr double kRatio = (1.0 + 99.0 / 21.0) * (92.0 / 21.0) * (107.0 / 26.0);

fs::path scratch(const std::string& name) {
  const fs::path p = fs::temp_directory_path() /
                     ("drivetwin-test-bundle-check-" + std::to_string(::getpid())) / name;
  fs::remove_all(p);
  return p;
}

struct Synth {
  double true_rpm = kRpm;       // what the signal says
  double true_rate_hz = 25600;  // rate the signal was sampled at
  std::size_t samples = 32768;
  bool tacho = true;
  double noise = 0.05;  // [m/s²] rms
};

// point1: hss mesh line (1 m/s²) and its 2nd harmonic, intermediate mesh line (0.3 m/s²),
// white noise; tacho: 5 V pulse over 2 % of every hss revolution.
hal::Recording synthesize(const Synth& s) {
  const double f_hss = s.true_rpm / 60.0 * kRatio;
  const double f_ims = s.true_rpm / 60.0 * (1.0 + 99.0 / 21.0) * (92.0 / 21.0);
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, s.noise);
  hal::Recording rec;
  rec.sample_rate_hz = s.true_rate_hz;
  rec.channels = {{"point1", "b5", "radial", "", "m/s^2"}};
  rec.samples.assign(1, std::vector<double>(s.samples));
  if (s.tacho) {
    rec.channels.push_back({"tacho", "hss", "", "once_per_rev", "V"});
    rec.samples.emplace_back(s.samples);
  }
  for (std::size_t i = 0; i < s.samples; ++i) {
    const double t = static_cast<double>(i) / s.true_rate_hz;
    rec.samples[0][i] = std::sin(2 * kPi * 26 * f_hss * t) +
                        0.4 * std::sin(2 * kPi * 52 * f_hss * t + 0.3) +
                        0.3 * std::sin(2 * kPi * 21 * f_ims * t + 1.0) + noise(rng);
    if (s.tacho) {
      const double rev = f_hss * t + 0.5;
      rec.samples[1][i] = rev - std::floor(rev) < 0.02 ? 5.0 : 0.0;
    }
  }
  rec.operating_point.rotor_speed_rpm = kRpm;
  rec.operating_point.input_torque_nm = 361747.0;
  return rec;
}

fs::path write(const std::string& name, const hal::Recording& rec) {
  const fs::path dir = scratch(name);
  const auto err = hal::write_bundle(dir, rec);
  EXPECT_FALSE(err) << err->to_string();
  return dir;
}

// The number printed right after `prefix` in `text` (NaN when absent).
double number_after(const std::string& text, const std::string& prefix) {
  const auto at = text.find(prefix);
  return at == std::string::npos ? std::nan("") : std::stod(text.substr(at + prefix.size()));
}

std::string refusal(const fs::path& dir) {
  try {
    (void)load_bundle(dir);
  } catch (const BundleCheckError& e) {
    return e.what();
  }
  return "";
}

TEST(BundleCheck, AGoodBundlePassesWithTachoMeshLinesAndMetadataAgreeing) {
  // Arrange
  const fs::path dir = write("good", synthesize({}));
  // Act
  const app::recording::CheckedBundle b = load_bundle(dir);
  // Assert: the tacho's mean rate through the ratio 103.02 gives 8.33 rpm; the mesh lines
  // sit where the metadata puts them (scale 1 within the 1.5 % search window).
  ASSERT_TRUE(b.tacho_rotor_rpm);
  EXPECT_NEAR(*b.tacho_rotor_rpm, kRpm, 0.01 * kRpm);
  ASSERT_TRUE(b.mesh_line_scale);
  EXPECT_NEAR(*b.mesh_line_scale, 1.0, 0.016);
  EXPECT_DOUBLE_EQ(b.input_torque_nm, 361747.0);
  EXPECT_FALSE(b.torque_estimated);
  EXPECT_EQ(b.drivetrain.name, "paper-2mw");
  fs::remove_all(dir);
}

TEST(BundleCheck, RefusesAMetadataSpeedTheTachoAndMeshLinesContradict) {
  // Arrange: the case — metadata 14 rpm, the signal at 8.33 rpm.
  hal::Recording rec = synthesize({});
  rec.operating_point.rotor_speed_rpm = 14.0;
  const fs::path dir = write("wrong-speed", rec);
  // Act
  const std::string e = refusal(dir);
  // Assert
  EXPECT_NE(e.find("recording.json: operating_point.rotor_speed_rpm: 14 rpm"), std::string::npos)
      << e;
  EXPECT_NE(e.find("both say 8.33"), std::string::npos) << e;
  fs::remove_all(dir);
}

TEST(BundleCheck, CalibrateAndDiagnoseRefuseTheContradictedSpeedExitingNonZeroWritingNothing) {
  // Arrange: the same bundle, through the two commands that read bundles.
  hal::Recording rec = synthesize({});
  rec.operating_point.rotor_speed_rpm = 14.0;
  const fs::path dir = write("wrong-speed-cli", rec);
  const fs::path json = dir.string() + ".json";
  for (const char* command : {"calibrate", "diagnose"}) {
    // Act
    const test_support::CommandResult r =
        test_support::run_command({command, dir.string(), "--json", json.string()});
    const std::string& out = r.out;
    // Assert
    EXPECT_EQ(r.exit_code, 1) << command;
    EXPECT_NE(r.error.find("recording.json: operating_point.rotor_speed_rpm: 14 rpm"),
              std::string::npos)
        << command << ": " << r.error;
    EXPECT_EQ(out.find("CALIBRATED"), std::string::npos) << command << ": " << out;
    EXPECT_FALSE(fs::exists(json)) << command;
  }
  fs::remove_all(dir);
}

TEST(BundleCheck, RefusesASampleRateDeclaredWrongWithATacho) {
  // Arrange: sampled at 25 600 Hz, declared 12 800 Hz: every frequency reads half, the
  // issue's "rotor 4.165 rpm".
  hal::Recording rec = synthesize({});
  rec.sample_rate_hz = 12800.0;
  const fs::path dir = write("wrong-rate-tacho", rec);
  // Act
  const std::string e = refusal(dir);
  // Assert: the tacho says 4.165 rpm; 25 600 Hz would reconcile it with the metadata.
  EXPECT_NE(e.find("operating_point.rotor_speed_rpm: 8.33 rpm, but the tacho 'tacho' says 4.16"),
            std::string::npos)
      << e;
  EXPECT_NEAR(number_after(e, "sample_rate_hz is wrong ("), 25600.0, 25.0) << e;
  fs::remove_all(dir);
}

TEST(BundleCheck, RefusesASampleRateDeclaredWrongFromTheMeshLinesAlone) {
  // Arrange: no tacho; a 25 600 Hz signal declared 51 200 Hz (every line at twice its
  // frequency) and 17 066 Hz (at 2/3). (Declared m times too LOW, the true m-th harmonics
  // land where the fundamentals belong: the mesh lines cannot tell, the tacho does —
  // see the test above; bundle_check.hpp says so.)
  Synth s;
  s.tacho = false;
  hal::Recording rec = synthesize(s);
  rec.sample_rate_hz = 51200.0;
  const fs::path dir_double = write("wrong-rate-double", rec);
  rec.sample_rate_hz = 17066.0;
  const fs::path dir_two_thirds = write("wrong-rate-two-thirds", rec);
  // Act
  const std::string twice = refusal(dir_double);
  const std::string two_thirds = refusal(dir_two_thirds);
  // Assert
  EXPECT_NE(twice.find("recording.json: sample_rate_hz: no gear-mesh line of point1 stands out"),
            std::string::npos)
      << twice;
  EXPECT_NEAR(number_after(twice, "the strongest family sits at "), 2.0, 0.01) << twice;
  EXPECT_NEAR(number_after(twice, "a sample rate of "), 25600.0, 0.005 * 25600) << twice;
  EXPECT_NEAR(number_after(two_thirds, "the strongest family sits at "), 2.0 / 3.0, 0.01)
      << two_thirds;
  EXPECT_NEAR(number_after(two_thirds, "a sample rate of "), 25600.0, 0.005 * 25600) << two_thirds;
  fs::remove_all(dir_double);
  fs::remove_all(dir_two_thirds);
}

TEST(BundleCheck, ATachoOnTheWrongShaftIsNamedWhenMeshLinesAgreeWithTheMetadata) {
  // Arrange: the tacho says it is on the ims, but pulses once per hss revolution.
  hal::Recording rec = synthesize({});
  rec.channels[1].location = "ims";
  const fs::path dir = write("tacho-shaft", rec);
  // Act
  const std::string e = refusal(dir);
  // Assert
  EXPECT_NE(e.find("channels[1]: tacho 'tacho' gives"), std::string::npos) << e;
  EXPECT_NE(e.find("check the tacho's shaft (location 'ims')"), std::string::npos) << e;
  fs::remove_all(dir);
}

TEST(BundleCheck, RefusesAnOperatingPointOutsideTheTurbinesRange) {
  // Arrange: the 5e7 N·m and 80 rpm (rated 1.23e6 N·m, 14.8 rpm).
  hal::Recording rec = synthesize({});
  rec.operating_point.input_torque_nm = 5e7;
  const fs::path torque = write("torque-range", rec);
  rec.operating_point.input_torque_nm = 361747.0;
  rec.operating_point.rotor_speed_rpm = 80.0;
  const fs::path speed = write("speed-range", rec);
  // Act + Assert: limits 150 % of rated torque (1.845e6 N·m), 120 % of rated speed (17.76).
  const std::string t = refusal(torque);
  EXPECT_NE(t.find("operating_point.input_torque_nm: is 5e+07; expected a finite value >= 0 and "
                   "<= 1845000"),
            std::string::npos)
      << t;
  const std::string s = refusal(speed);
  EXPECT_NE(s.find("operating_point.rotor_speed_rpm: is 80"), std::string::npos) << s;
  EXPECT_NE(s.find("<= 17.76"), std::string::npos) << s;
  fs::remove_all(torque);
  fs::remove_all(speed);
}

TEST(BundleCheck, OnlyAWindSpeedGivesTheWindModelsTorqueAndSaysSo) {
  // Arrange: the paper's check point without its torque: 6.75 m/s at 8.33 rpm.
  hal::Recording rec = synthesize({});
  rec.operating_point.input_torque_nm.reset();
  rec.operating_point.wind_speed_mps = 6.75;
  const fs::path dir = write("wind-only", rec);
  // Act
  const app::recording::CheckedBundle b = load_bundle(dir);
  // Assert: the paper gives 361 747 N·m at that point (drivetrain-2mw.md); the wind load model
  // reproduces it within a few per cent (its surface follows that check point).
  EXPECT_TRUE(b.torque_estimated);
  EXPECT_NEAR(b.input_torque_nm / 361747.0, 1.0, 0.05);
  bool noted = false;
  for (const auto& n : b.notes)
    noted |= n.find("estimated from wind_speed_mps 6.75") != std::string::npos;
  EXPECT_TRUE(noted);
  fs::remove_all(dir);
}

TEST(BundleCheck, AChannelInGIsConvertedAndItsMeshLinesStillCheck) {
  // Arrange: the same signal expressed in g.
  hal::Recording rec = synthesize({});
  for (double& v : rec.samples[0]) v /= 9.80665;
  rec.channels[0].unit = "g";
  const fs::path dir = write("in-g", rec);
  // Act
  const app::recording::CheckedBundle b = load_bundle(dir);
  // Assert
  EXPECT_EQ(b.recording.channels[0].unit, "m/s^2");
  double rms = 0.0;
  for (double v : b.recording.samples[0]) rms += v * v;
  rms = std::sqrt(rms / static_cast<double>(b.recording.samples[0].size()));
  // sines of 1, 0.4 and 0.3 m/s² plus 0.05 noise: rms = sqrt((1 + 0.16 + 0.09)/2 + 0.0025)
  EXPECT_NEAR(rms, std::sqrt(1.25 / 2 + 0.0025), 0.01);
  bool noted = false;
  for (const auto& n : b.notes) noted |= n.find("converted from g to m/s^2") != std::string::npos;
  EXPECT_TRUE(noted);
  fs::remove_all(dir);
}

TEST(BundleCheck, RefusesALocationThatIsNotAComponentAndAnUnknownDrivetrain) {
  // Arrange
  hal::Recording rec = synthesize({});
  rec.channels[0].location = "b9";
  const fs::path location = write("location", rec);
  rec.channels[0].location = "b5";
  rec.drivetrain = "no-such-gearbox";
  const fs::path drivetrain = write("drivetrain", rec);
  // Act + Assert
  const std::string l = refusal(location);
  EXPECT_NE(l.find("channels[0].location: 'b9' is not a component of drivetrain 'paper-2mw'"),
            std::string::npos)
      << l;
  const std::string d = refusal(drivetrain);
  EXPECT_NE(d.find("recording.json: drivetrain: 'no-such-gearbox' is neither a built-in"),
            std::string::npos)
      << d;
  fs::remove_all(location);
  fs::remove_all(drivetrain);
}

TEST(BundleCheck, NoiseWithoutMeshLinesIsNotRefusedButReportedUnchecked) {
  // Arrange: pure noise, no tacho.
  Synth s;
  s.tacho = false;
  hal::Recording rec = synthesize(s);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (double& v : rec.samples[0]) v = noise(rng);
  const fs::path dir = write("noise", rec);
  // Act
  const app::recording::CheckedBundle b = load_bundle(dir);
  // Assert
  EXPECT_FALSE(b.mesh_line_scale);
  bool noted = false;
  for (const auto& n : b.notes) noted |= n.find("not checked") != std::string::npos;
  EXPECT_TRUE(noted);
  fs::remove_all(dir);
}

}  // namespace
