#pragma once
// `drivetwin run --replay` against `drivetwin damage --spectrum dynamics-rows` on the same
// SCADA rows with the same ROM (step and cut-off): the loop's damage per gear and bearing
// channel must equal the offline path's within `tolerance` (relative).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "loop/runner.hpp"
#include "run/run_config.hpp"
#include "run_test_util.hpp"
#include "support/run_command.hpp"

namespace run_test {

/// Replays the built-in day's first `rows` rows with the ROM at `steps` steps per 15.625 ms
/// cycle and cut-off `cutoff_hz`, runs `drivetwin damage` on the same rows, and compares.
inline void expect_replay_equals_damage(std::size_t rows, int steps, double cutoff_hz,
                                        double tolerance) {
  // Arrange
  TempDir dir("dt-replay-damage");
  const fs::path csv = dir.path / "day.csv";
  write(csv, builtin_day_rows(rows + 1));  // + 1: the period of the last row replayed
  write(dir.path / "bus.toml", "format = \"drivetwin-bus/1\"\n[scada]\nbackend = \"none\"\n");
  std::ostringstream run;
  run << "format = \"drivetwin-run/1\"\n[twin]\nbus = \"bus.toml\"\n"
      << "[loop]\nperiod_us = 15625\nrom_steps_per_cycle = " << steps
      << "\nrom_cutoff_hz = " << cutoff_hz << "\npublish_divisor = 64\n"
      << "[calibration]\nenabled = false\n[threads.rt_loop]\npolicy = \"other\"\npriority = 0\n";
  write(dir.path / "twin.toml", run.str());
  app::run::RunConfig c = app::run::load_run_config(dir.path / "twin.toml");
  c.state_dir = (dir.path / "state").string();
  const double rate_hz = steps / 0.015625;
  // Act: the offline path on the first `rows` rows (its own file), then the loop on the
  // same rows (the replay stops at the end of the last one: --duration).
  write(dir.path / "rows.csv", builtin_day_rows(rows));
  const fs::path json = dir.path / "damage.json";
  std::ostringstream rate, cut;
  rate << rate_hz;
  cut << cutoff_hz;
  const test_support::CommandResult d = test_support::run_command(
      {"damage", (dir.path / "rows.csv").string(), "--period", "600", "--spectrum", "dynamics-rows",
       "--rom-rate", rate.str(), "--rom-cutoff", cut.str(), "--json", json.string(),
       "--no-progress"});
  ASSERT_EQ(d.exit_code, 0) << d.error;
  app::loop::RunOptions o;
  o.replay = csv.string();
  o.duration_s = 600.0 * static_cast<double>(rows);
  std::ostringstream log;
  o.log = &log;
  const app::loop::RunSummary s = app::loop::run_twin(c, o);
  // Assert: the same time, and every channel's damage within the tolerance.
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_DOUBLE_EQ(j["covered_s"].get<double>(), s.elapsed_s) << log.str();
  ASSERT_EQ(j["channels"].size(), s.damage.size());
  double worst = 0.0;
  for (std::size_t c2 = 0; c2 < s.damage.size(); ++c2) {
    const double offline = j["channels"][c2]["damage"].get<double>();
    ASSERT_GT(offline, 0.0) << s.channel_names[c2];
    const double rel = (s.damage[c2] - offline) / offline;
    worst = std::max(worst, std::abs(rel));
    EXPECT_LE(std::abs(rel), tolerance)
        << s.channel_names[c2] << ": loop " << s.damage[c2] << ", damage " << offline;
  }
  ::testing::Test::RecordProperty("worst_relative_difference", std::to_string(worst));
  std::printf("# %zu rows, ROM %.0f Hz / %.0f Hz: largest |loop − damage| / damage %.3f %%\n", rows,
              rate_hz, cutoff_hz, 100.0 * worst);
}

}  // namespace run_test
