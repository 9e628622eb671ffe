// `drivetwin calibrate` end to end on bundles written to a temporary directory:
// an off-nominal recording is calibrated to within the thresholds, and every
// bad input (missing, flat, clipped channel, too short a recording) is refused
// with a message naming the file and channel, and nothing is written.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli/run.hpp"
#include "config/drivetrain_file.hpp"
#include "hal/recording_bundle.hpp"
#include "model/calibration/lumped_simulator.hpp"

namespace {

namespace fs = std::filesystem;
namespace mc = model::calibration;

fs::path scratch_dir(const std::string& name) {
  const fs::path p =
      fs::temp_directory_path() / ("drivetwin-test-calibrate-" + std::to_string(::getpid())) / name;
  fs::remove_all(p);
  return p;
}

enum class Fault { kNone, kDropPoint2, kFlatPoint2, kClipPoint1 };

// Table 3 drift (damping ×2, mesh ×0.8, bearing ×1.3), 5 % noise, paper operating point;
// `hss_mesh_scale` replaces the high-speed stage's 0.8.
fs::path write_bundle(const std::string& name, double duration_s, Fault fault = Fault::kNone,
                      double hss_mesh_scale = 0.8) {
  const model::Drivetrain d = model::paper_2mw();
  model::DynamicsParameters truth = mc::with_nominal_damping(d.dynamics);
  truth.rayleigh_eta *= 2.0;
  truth.rayleigh_zeta *= 2.0;
  truth.mesh_stiffness_scale = {0.8, 0.8, hss_mesh_scale};
  truth.bearing_stiffness_scale = {1.3, 1.3, 1.3};
  mc::LumpedSimulatorConfig sc;
  sc.sample_rate_hz = 8192.0;
  sc.max_duration_s = duration_s;
  sc.noise_relative = 0.05;
  mc::LumpedSimulator sim(d, sc);
  std::array<mc::WaveformView, mc::kMeasurementPoints> w{};
  EXPECT_TRUE(sim.simulate(truth, {8.33, 361747.0}, duration_s, w));
  hal::Recording rec;
  rec.sample_rate_hz = sc.sample_rate_hz;
  rec.channels = {{"point1", "b5", "radial", "", "m/s^2"}, {"point2", "b3", "radial", "", "m/s^2"}};
  rec.samples = {std::vector<double>(w[0].samples, w[0].samples + w[0].count),
                 std::vector<double>(w[1].samples, w[1].samples + w[1].count)};
  rec.operating_point.rotor_speed_rpm = 8.33;
  rec.operating_point.input_torque_nm = 361747.0;
  switch (fault) {
    case Fault::kNone:
      break;
    case Fault::kDropPoint2:
      rec.channels.pop_back();
      rec.samples.pop_back();
      break;
    case Fault::kFlatPoint2:
      std::fill(rec.samples[1].begin(), rec.samples[1].end(), 0.0);
      break;
    case Fault::kClipPoint1: {
      double peak = 0.0;
      for (double v : rec.samples[0]) peak = std::max(peak, std::abs(v));
      for (double& v : rec.samples[0]) v = std::clamp(v, -0.6 * peak, 0.6 * peak);
      break;
    }
  }
  const fs::path dir = scratch_dir(name);
  const auto err = hal::write_bundle(dir, rec);
  EXPECT_FALSE(err.has_value()) << (err ? err->to_string() : "");
  return dir;
}

// Runs `drivetwin calibrate <args>` as main() would; returns the error text ("" when none).
std::string run_calibrate(std::vector<std::string> args) {
  // A small analysis so that the test stays quick (also under QEMU).
  for (const char* a : {"--revolutions", "32", "--samples-per-rev", "256", "--quiet"})
    args.emplace_back(a);
  args.insert(args.begin(), "calibrate");
  return app::cli::run(args).error;
}

TEST(CalibrateCommand, CalibratesAnOffNominalRecordingAndReportsTheDiagnosisKeys) {
  // Arrange
  const fs::path dir = write_bundle("drift", 3.0);
  const fs::path json = dir.parent_path() / "drift.json";
  // Act
  // (the bundle comes from the lumped stand-in, so the stand-in calibrates it)
  const std::string error =
      run_calibrate({dir.string(), "--json", json.string(), "--simulator", "lumped", "--method",
                     "improved", "--population", "16", "--iterations", "15", "--seed", "3"});
  // Assert
  ASSERT_EQ(error, "");
  EXPECT_EQ(app::cli::exit_status(), 0);
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  bool some_above = false;
  for (const char* p : {"point1", "point2"}) {
    const auto& b = j["fit_before"][p];
    some_above = some_above || b["f1"].get<double>() > 0.5 || b["f2"].get<double>() > 0.2 ||
                 b["f3"].get<double>() > 0.2;
    const auto& a = j["fit_calibrated"][p];
    EXPECT_LE(a["f1"].get<double>(), 0.5) << p;
    EXPECT_LE(a["f2"].get<double>(), 0.2) << p;
    EXPECT_LE(a["f3"].get<double>(), 0.2) << p;
  }
  EXPECT_TRUE(some_above);
  EXPECT_TRUE(j["fits"].get<bool>());
  EXPECT_TRUE(j.contains("residual_before"));
  EXPECT_LT(j["residual_calibrated"].get<double>(), j["residual_before"].get<double>());
  EXPECT_EQ(j["parameters_calibrated"]["mesh_stiffness_scale"].size(), 3u);
  EXPECT_GT(j["evaluations_to_threshold"].get<int>(), 0);
}

struct BadInput {
  const char* name;
  double duration_s;
  Fault fault;
  const char* expected;  // in the message, besides the bundle path
};

TEST(CalibrateCommand, RefusesBadInputWithAMessageNamingFileAndChannelAndWritesNothing) {
  for (const BadInput& bad :
       {BadInput{"missing", 3.0, Fault::kDropPoint2,
                 "recording.json: channels: no channel named 'point2'"},
        BadInput{"flat", 3.0, Fault::kFlatPoint2, "channel 'point2': channel is flat"},
        BadInput{"clipped", 3.0, Fault::kClipPoint1, "channel 'point1': channel is clipped"},
        BadInput{"short", 1.0, Fault::kNone,
                 "channel 'point1': recording of 1.00 s is too short"}}) {
    const fs::path dir = write_bundle(bad.name, bad.duration_s, bad.fault);
    const fs::path json = dir.parent_path() / (std::string(bad.name) + ".json");
    const std::string error = run_calibrate({dir.string(), "--json", json.string()});
    EXPECT_NE(error.find(bad.expected), std::string::npos) << bad.name << ": " << error;
    EXPECT_NE(error.find(dir.string()), std::string::npos) << bad.name << ": " << error;
    EXPECT_FALSE(fs::exists(json)) << bad.name;
  }
}

// Issue 15, finding 2 at the command line: a parameter pinned at its bound was reported
// CALIBRATED (exit 0), and calibrate could not write its result back.
TEST(CalibrateCommand, AVariablePinnedAtItsBoundIsNotCalibratedAndUpdateWritesNothing) {
  // Arrange: the high-speed mesh scale 0.3, below the paper space's bound 0.5.
  const fs::path dir = write_bundle("pinned", 3.0, Fault::kNone, 0.3);
  const fs::path json = dir.parent_path() / "pinned.json";
  const fs::path update = dir.parent_path() / "pinned.toml";
  // Act
  testing::internal::CaptureStderr();
  const std::string error = run_calibrate(
      {dir.string(), "--json", json.string(), "--simulator", "lumped", "--method", "improved",
       "--population", "16", "--iterations", "15", "--seed", "3", "--update", update.string()});
  const std::string err = testing::internal::GetCapturedStderr();
  // Assert: exit 2, not calibrated, the variable at its bound, the description not written.
  ASSERT_EQ(error, "");
  EXPECT_EQ(app::cli::exit_status(), 2);
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_TRUE(j["at_bound"].get<bool>());
  EXPECT_FALSE(j["calibrated"].get<bool>());
  bool found = false;
  for (const auto& v : j["variables"]) {
    if (v["name"] != "mesh_stiffness_scale.stage3") continue;
    found = true;
    EXPECT_EQ(v["status"], "AT LOWER BOUND") << v;
    EXPECT_NEAR(v["value"].get<double>(), 0.5, 1e-3) << v;
  }
  EXPECT_TRUE(found);
  EXPECT_FALSE(fs::exists(update));
  EXPECT_NE(err.find("not written (the result is NOT CALIBRATED)"), std::string::npos) << err;
}

TEST(CalibrateCommand,
     UpdateWritesTheCalibratedParametersIntoADescriptionThatThenFitsTheRecording) {
  // Arrange
  const fs::path dir = write_bundle("update", 3.0);
  const fs::path json = dir.parent_path() / "update.json";
  const fs::path again = dir.parent_path() / "update-again.json";
  const fs::path update = dir.parent_path() / "update.toml";
  const std::vector<std::string> lumped{"--simulator",  "lumped", "--method",     "improved",
                                        "--population", "16",     "--iterations", "15",
                                        "--seed",       "3"};
  std::vector<std::string> args{dir.string(), "--json", json.string(), "--update", update.string()};
  args.insert(args.end(), lumped.begin(), lumped.end());
  // Act
  ASSERT_EQ(run_calibrate(args), "");
  ASSERT_EQ(app::cli::exit_status(), 0);
  // Assert: the file is a description the reader takes, holding the calibrated parameters...
  ASSERT_TRUE(fs::exists(update));
  const model::Drivetrain d = app::config::load_drivetrain(update.string());
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  const auto& p = j["parameters_calibrated"];
  EXPECT_DOUBLE_EQ(d.dynamics.rayleigh_eta, p["rayleigh_eta_1_s"].get<double>());
  EXPECT_DOUBLE_EQ(d.dynamics.rayleigh_zeta, p["rayleigh_zeta_s"].get<double>());
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_DOUBLE_EQ(d.dynamics.mesh_stiffness_scale[i],
                     p["mesh_stiffness_scale"][i].get<double>());
    EXPECT_DOUBLE_EQ(d.dynamics.bearing_stiffness_scale[i],
                     p["bearing_stiffness_scale"][i].get<double>());
  }
  // ... and, as the prior of the next calibration, fits the recording: nothing left to do.
  std::vector<std::string> next{dir.string(), "--json", again.string(), "--drivetrain",
                                update.string()};
  next.insert(next.end(), lumped.begin(), lumped.end());
  ASSERT_EQ(run_calibrate(next), "");
  EXPECT_EQ(app::cli::exit_status(), 0);
  std::ifstream in2(again);
  const nlohmann::json k = nlohmann::json::parse(in2);
  EXPECT_FALSE(k["calibration_ran"].get<bool>()) << k["fit_before"];
  EXPECT_TRUE(k["calibrated"].get<bool>());
}

}  // namespace
