// The calibrate null test at the command line (issue 15): the model's own recording —
// `drivetwin simulate` at nominal parameters, settled (its default run-in) — with the
// white noise of a real accelerometer added, fed to `drivetwin calibrate`:
//   - every indicator is under its threshold before calibration, so calibrate says no
//     calibration is needed, changes nothing and exits 0;
//   - a calibration forced on it (--force) moves no parameter by more than the noise
//     warrants: a variable the recording cannot identify stays exactly at its prior, an
//     identified one within k of its posterior standard deviations, the σ the calibrator
//     itself reports from the recording (the tolerance is not tuned here: k is the
//     Bonferroni bound that keeps the chance of any of the N identified variables straying
//     that far by noise alone below 1 %), and the verdict is CALIBRATED with nothing at a
//     bound.
// Issue 15 found the opposite: the recording's start-up transient made calibrate "correct"
// a perfect model (η 5 → 3.16, ζ 1e-5 → 7.2e-6, hss mesh scale 0.865) and print CALIBRATED.
// Heavy (a forced calibration runs the ROM ~150 times): host only.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "hal/recording_bundle.hpp"
#include "support/run_command.hpp"

namespace {

namespace fs = std::filesystem;
using test_support::CommandResult;
using test_support::run_command;

// Accelerometer noise: white, 5 % of each channel's RMS — the level the calibration and
// diagnosis test generators use for a CMS channel (tools/calibration, tools/truth).
constexpr double kNoiseRelative = 0.05;

// The paper's thresholds of the similarity indicators (docs/calibration.md).
constexpr double kF1Max = 0.5, kF2Max = 0.2, kF3Max = 0.2;

// Φ⁻¹(p) by bisection on erfc (no tuning: the standard normal quantile).
double normal_quantile(double p) {
  double lo = -10.0, hi = 10.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(-mid / std::sqrt(2.0)) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

class CalibrateNullTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("drivetwin_calibrate_null_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // The model's own settled recording at the parameters of `drivetrain` (a built-in name or a
  // description file), with accelerometer noise.
  fs::path own_recording_with_noise(const std::string& drivetrain) {
    const fs::path clean = dir_ / "clean";
    // 5 s: one analysis block of calibrate's default 64 hss revolutions (4.5 s at 8.33 rpm).
    const CommandResult sim =
        run_command({"simulate", "--drivetrain", drivetrain, "--rpm", "8.33", "--torque", "361747",
                     "--seconds", "5", "--out", clean.string(), "--no-loads", "--no-progress"});
    EXPECT_EQ(sim.exit_code, 0) << sim;
    EXPECT_NE(sim.out.find("run-in"), std::string::npos) << sim.out;  // settled, and says so
    hal::BundleReadResult read = hal::read_bundle(clean);
    EXPECT_TRUE(read) << read.error.to_string();
    if (!read) return {};
    hal::Recording rec = *read.recording;
    std::mt19937_64 rng(15);
    std::normal_distribution<double> unit(0.0, 1.0);
    for (std::size_t c = 0; c < rec.channels.size(); ++c) {
      if (rec.channels[c].unit != "m/s^2") continue;  // the tacho stays clean
      double sum2 = 0.0;
      for (double v : rec.samples[c]) sum2 += v * v;
      const double sigma =
          kNoiseRelative * std::sqrt(sum2 / static_cast<double>(rec.samples[c].size()));
      for (double& v : rec.samples[c]) v += sigma * unit(rng);
    }
    const fs::path noisy = dir_ / "noisy";
    const auto err = hal::write_bundle(noisy, rec);
    EXPECT_FALSE(err.has_value()) << (err ? err->to_string() : "");
    return noisy;
  }

  void expect_null(const std::string& drivetrain);

  static nlohmann::json read_json(const fs::path& path) {
    std::ifstream in(path);
    return nlohmann::json::parse(in);
  }

  static void expect_under_thresholds(const nlohmann::json& fit, const char* what) {
    for (const char* p : {"point1", "point2"}) {
      EXPECT_LE(fit[p]["f1"].get<double>(), kF1Max) << what << " " << p;
      EXPECT_LE(fit[p]["f2"].get<double>(), kF2Max) << what << " " << p;
      EXPECT_LE(fit[p]["f3"].get<double>(), kF3Max) << what << " " << p;
      EXPECT_TRUE(fit[p]["valid"].get<bool>()) << what << " " << p;
    }
  }

  fs::path dir_;
};

// Plain and forced calibration of `drivetrain`'s own noisy recording against `drivetrain`.
void CalibrateNullTest::expect_null(const std::string& drivetrain) {
  // Arrange
  const fs::path bundle = own_recording_with_noise(drivetrain);
  ASSERT_FALSE(bundle.empty());
  const fs::path plain_json = dir_ / "plain.json", forced_json = dir_ / "forced.json";

  // Act: as a user runs it, then forced.
  const CommandResult plain = run_command(
      {"calibrate", bundle.string(), "--drivetrain", drivetrain, "--json", plain_json.string()});
  const CommandResult forced =
      run_command({"calibrate", bundle.string(), "--drivetrain", drivetrain, "--json",
                   forced_json.string(), "--force", "--quiet"});

  // Assert: under every threshold before calibration; nothing to do, nothing changed.
  ASSERT_EQ(plain.exit_code, 0) << plain;
  EXPECT_NE(plain.out.find("no calibration needed"), std::string::npos) << plain.out;
  const nlohmann::json p = read_json(plain_json);
  expect_under_thresholds(p["fit_before"], "before");
  EXPECT_FALSE(p["calibration_ran"].get<bool>());
  EXPECT_TRUE(p["calibrated"].get<bool>());
  for (const auto& v : p["variables"]) {
    EXPECT_EQ(v["value"].get<double>(), v["prior"].get<double>()) << v["name"];
  }
  // The default model selection: the standard space explains it, the body is never tried.
  EXPECT_EQ(p["model_selection"]["chosen"], "standard") << p["model_selection"];
  EXPECT_EQ(p["model_selection"]["tried"].size(), 1u) << p["model_selection"];

  // Forced: CALIBRATED, nothing at a bound, every variable where the noise lets it be.
  ASSERT_EQ(forced.exit_code, 0) << forced;
  const nlohmann::json f = read_json(forced_json);
  ASSERT_TRUE(f["calibration_ran"].get<bool>());
  EXPECT_TRUE(f["calibrated"].get<bool>());
  EXPECT_FALSE(f["at_bound"].get<bool>());
  expect_under_thresholds(f["fit_calibrated"], "calibrated");
  EXPECT_EQ(f["model_selection"]["chosen"], "standard") << f["model_selection"];
  EXPECT_EQ(f["model_selection"]["tried"].size(), 1u) << f["model_selection"];
  // The planetary stage's torsional mode is where the model has it: the scan of the sun
  // shaft's torsion (resonance_placement.hpp) finds nothing lower by its threshold, no refit.
  ASSERT_TRUE(f["resonance_placement"].is_object()) << f["resonance_placement"];
  EXPECT_FALSE(f["resonance_placement"]["refit"].get<bool>()) << f["resonance_placement"];
  EXPECT_EQ(f["resonance_placement"]["grid"].size(), 9u);
  std::size_t identified = 0;
  for (const auto& v : f["variables"]) identified += v["status"] == "identified" ? 1 : 0;
  ASSERT_GT(identified, 0u);
  const double k = normal_quantile(1.0 - 0.01 / (2.0 * static_cast<double>(identified)));
  double largest = 0.0;
  std::string largest_name;
  for (const auto& v : f["variables"]) {
    const std::string name = v["name"].get<std::string>();
    if (v["status"] != "identified") {
      // Kept where it started (to rounding: the value goes through its whitened variable).
      EXPECT_EQ(v["status"], "not identified") << name;
      const double prior = v["prior"].get<double>();
      EXPECT_NEAR(v["value"].get<double>(), prior, 1e-12 * std::max(1.0, std::abs(prior))) << name;
      continue;
    }
    // z: the move from the prior in prior σ (whitened); posterior σ = ratio × prior σ.
    const double z = v["z"].get<double>();
    const double posterior = v["posterior_sd_ratio"].get<double>();
    if (std::abs(z) / posterior > largest) {
      largest = std::abs(z) / posterior;
      largest_name = name;
    }
    EXPECT_LE(std::abs(z), k * posterior)
        << name << ": moved " << z << " prior sd, " << std::abs(z) / posterior
        << " posterior sd (noise warrants at most " << k << ")";
  }
  std::printf(
      "null test: %zu variables identified, k = %.2f; largest move %.2f posterior sd (%s)\n",
      identified, k, largest, largest_name.c_str());
}

TEST_F(CalibrateNullTest,
       TheModelsOwnSettledRecordingNeedsNoCalibrationAndAForcedOneMovesNothingBeyondTheNoise) {
  expect_null("paper-2mw");
}

// Issue 12: the calibrated twin's own recording at its calibrated parameters, calibrated again,
// moves nothing beyond what the noise warrants. The description is what `calibrate --update`
// wrote for a recording of a gearbox the twin did not simulate (the independent generator,
// seed 2 at the paper's point, docs/calibration.md): tip relief, transmission errors with
// their phases, housing modes and bearing stiffnesses all away from the nominal model's.
TEST_F(CalibrateNullTest, TheCalibratedTwinsOwnRecordingCalibratedAgainMovesNothingBeyondTheNoise) {
  expect_null((fs::path(DRIVETWIN_FIXTURES_DIR) / "calibration" / "calibrated-generator-seed2.toml")
                  .string());
}

// The resonance placement's released refit (resonance_placement.hpp, docs/calibration.md
// Session 15), on a recording whose planetary torsional mode is not where the description has
// it: the model's own recording with its sun shaft 4× stiffer (the mode at ~182 Hz instead of
// 118.7 Hz), calibrated against the description. The truth is known, so the expectation is
// independent: the scan finds a lower residual away from the description, the refit with the
// scale released is kept, and it ends within one grid step (×9^(2/9) = ×1.63, the scan's
// resolution) of 4 — not at the description's 1, not at a bound.
TEST_F(CalibrateNullTest, ASunShaftStifferThanTheDescriptionsIsPlacedAndFittedNearItsTrueValue) {
  // Arrange: the description as a file, its sun shaft ×4.
  const CommandResult desc = run_command({"drivetrain", "--drivetrain", "paper-2mw"});
  ASSERT_EQ(desc.exit_code, 0) << desc;
  const std::string key = "sun_shaft_torsion_scale = 1.0";
  std::string text = desc.out;
  const std::size_t at = text.find(key);
  ASSERT_NE(at, std::string::npos) << "the description prints " << key;
  text.replace(at, key.size(), "sun_shaft_torsion_scale = 4.0");
  const fs::path stiff = dir_ / "stiff-sun.toml";
  std::ofstream(stiff) << text;
  const fs::path bundle = own_recording_with_noise(stiff.string());
  ASSERT_FALSE(bundle.empty());
  const fs::path json = dir_ / "placed.json";

  // Act
  const CommandResult r = run_command({"calibrate", bundle.string(), "--drivetrain", "paper-2mw",
                                       "--json", json.string(), "--force", "--quiet"});

  // Assert
  ASSERT_EQ(r.exit_code, 0) << r;
  const nlohmann::json j = read_json(json);
  const nlohmann::json& place = j["resonance_placement"];
  ASSERT_TRUE(place.is_object()) << j;
  EXPECT_EQ(place["fitted"].get<double>(), 1.0) << place;  // the first fit leaves it alone
  ASSERT_TRUE(place["refit"].get<bool>()) << place;
  EXPECT_TRUE(place["released"].get<bool>()) << place;
  EXPECT_EQ(place["kept"], "refit") << place;
  EXPECT_LT(place["residual_unclipped_refit"].get<double>(),
            place["residual_unclipped_at_fit"].get<double>())
      << place;
  const double step = std::pow(9.0, 2.0 / 9.0);
  const double placed = j["parameters_calibrated"]["sun_shaft_torsion_scale"].get<double>();
  EXPECT_EQ(placed, place["refit_value"].get<double>());
  EXPECT_LT(std::abs(std::log(placed / 4.0)), std::log(step)) << placed;
  EXPECT_TRUE(j["calibrated"].get<bool>()) << j["fit_calibrated"];
  EXPECT_FALSE(j["at_bound"].get<bool>());
  // The released variable is reported with the others, its prior the description's.
  bool reported = false;
  for (const auto& v : j["variables"]) {
    if (v["name"] != "sun_shaft_torsion_scale") continue;
    reported = true;
    EXPECT_EQ(v["prior"].get<double>(), 1.0);
    EXPECT_EQ(v["value"].get<double>(), placed);
  }
  EXPECT_TRUE(reported);
  double lowest = place["residual_unclipped_at_fit"].get<double>();
  for (const auto& g : place["grid"])
    lowest = std::min(lowest, g["residual_unclipped"].get<double>());
  std::printf(
      "placement: scan best %.3g (residual %.3f -> %.3f); released refit ends at %.3g (truth 4), "
      "residual %.3f\n",
      place["best"].get<double>(), place["residual_unclipped_at_fit"].get<double>(), lowest, placed,
      place["residual_unclipped_refit"].get<double>());
}

}  // namespace
