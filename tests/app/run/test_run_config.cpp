// The run configuration (app/run/run_config.hpp): defaults from the one parameter table,
// errors that name the file, line and key, the thread table overrides, the shipped files.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "bus/bus_config.hpp"
#include "run/run_config.hpp"

namespace {

using app::run::parse_run_config;
using app::run::RunConfig;
using app::run::RunConfigError;

constexpr const char* kHead = "format = \"drivetwin-run/1\"\n";

std::string error_of(const std::string& text) {
  try {
    (void)parse_run_config(text, "dir/twin.toml");
  } catch (const RunConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(RunConfig, AnEmptyFileGivesEveryDefaultOfTheTable) {
  // Act
  const RunConfig c = parse_run_config(kHead, "dir/twin.toml");
  // Assert: the table's defaults, paths resolved against the file's folder.
  EXPECT_EQ(c.period_us, 1000);
  EXPECT_EQ(c.rom_steps_per_cycle, 8);
  EXPECT_DOUBLE_EQ(c.accel_hf_bc_mps2, 7.5);
  EXPECT_DOUBLE_EQ(c.velocity_cd_mmps, 5.6);
  EXPECT_EQ(c.drivetrain, "paper-2mw");
  EXPECT_EQ(c.bus, "dir/bus.toml");
  EXPECT_EQ(c.state_dir, "dir/state");
  EXPECT_EQ(c.thread(app::run::ThreadId::kRtLoop).policy, hal::SchedPolicy::kFifo);
  EXPECT_EQ(c.thread(app::run::ThreadId::kCalibration).policy, hal::SchedPolicy::kIdle);
  // Every parameter of the table is documented.
  for (const app::run::Param& p : app::run::run_parameters()) {
    EXPECT_FALSE(p.description.empty()) << p.key;
    EXPECT_FALSE(p.default_text.empty()) << p.key;
  }
}

TEST(RunConfig, ValuesOverrideDefaultsAndThreadEntriesReachTheTable) {
  const RunConfig c = parse_run_config(std::string(kHead) +
                                           "[loop]\nperiod_us = 2000\n"
                                           "[threads.rt_loop]\npolicy = \"rr\"\npriority = 42\n"
                                           "cpu = 1\nstack_kib = 64\n"
                                           "[vibration]\nalarm_zone = \"C\"\n",
                                       "twin.toml");
  EXPECT_EQ(c.period_us, 2000);
  const hal::ThreadAttributes& rt = c.thread(app::run::ThreadId::kRtLoop);
  EXPECT_EQ(rt.policy, hal::SchedPolicy::kRoundRobin);
  EXPECT_EQ(rt.priority, 42);
  EXPECT_EQ(rt.cpu, 1);
  EXPECT_EQ(rt.stack_bytes, 64u * 1024u);
  EXPECT_EQ(c.alarm_zone, 1);
}

TEST(RunConfig, ErrorsNameTheFileTheLineAndTheKey) {
  // Unknown key: named, with the keys that would have been right.
  std::string e = error_of(std::string(kHead) + "[loop]\nperiod_ms = 2\n");
  EXPECT_NE(e.find("dir/twin.toml:3: loop.period_ms: unknown key"), std::string::npos) << e;
  EXPECT_NE(e.find("period_us"), std::string::npos) << e;
  // Out of range: the range and unit.
  e = error_of(std::string(kHead) + "[loop]\nperiod_us = 5\n");
  EXPECT_NE(e.find("loop.period_us: is 5; expected an integer in [100, 100000]"), std::string::npos)
      << e;
  // Wrong type.
  e = error_of(std::string(kHead) + "[calibration]\nenabled = \"yes\"\n");
  EXPECT_NE(e.find("calibration.enabled: expected true or false"), std::string::npos) << e;
  // Unknown choice.
  e = error_of(std::string(kHead) + "[inputs]\ntorque_source = \"anemometer\"\n");
  EXPECT_NE(e.find("expected one of: auto, torque, power, wind"), std::string::npos) << e;
  // Unknown table, missing or wrong format, a TOML syntax error.
  e = error_of(std::string(kHead) + "[loops]\nx = 1\n");
  EXPECT_NE(e.find("loops: unknown table"), std::string::npos) << e;
  e = error_of("[loop]\n");
  EXPECT_NE(e.find("format: missing"), std::string::npos) << e;
  e = error_of("format = \"drivetwin-bus/1\"\n");
  EXPECT_NE(e.find("expected \"drivetwin-run/1\""), std::string::npos) << e;
  e = error_of(std::string(kHead) + "[loop\n");
  EXPECT_NE(e.find("dir/twin.toml:2"), std::string::npos) << e;
  // A non-finite number.
  e = error_of(std::string(kHead) + "[inputs]\nscada_hold_s = nan\n");
  EXPECT_NE(e.find("inputs.scada_hold_s"), std::string::npos) << e;
}

TEST(RunConfig, RelationsBetweenKeysAreChecked) {
  std::string e = error_of(std::string(kHead) + "[vibration]\naccel_hf_cd_mps2 = 7.0\n");
  EXPECT_NE(e.find("vibration.accel_hf_cd_mps2: must be above vibration.accel_hf_bc_mps2"),
            std::string::npos)
      << e;
  e = error_of(std::string(kHead) + "[vibration]\npoint2_channel = 0\n");
  EXPECT_NE(e.find("vibration.point2_channel: must differ"), std::string::npos) << e;
  e = error_of(std::string(kHead) + "[threads.rt_loop]\npolicy = \"fifo\"\npriority = 0\n");
  EXPECT_NE(e.find("threads.rt_loop"), std::string::npos) << e;
}

TEST(RunConfig, TheReferenceListsEveryKeyOnce) {
  const std::string ref = app::run::run_config_reference();
  std::set<std::string> keys;
  for (const app::run::Param& p : app::run::run_parameters()) {
    EXPECT_TRUE(keys.insert(p.key).second) << "declared twice: " << p.key;
    EXPECT_NE(ref.find("| `" + p.key + "` |"), std::string::npos) << p.key;
  }
}

TEST(RunConfig, TheDocumentationCarriesTheCurrentReference) {
  // docs/run.md embeds `drivetwin run --config-reference` between two markers.
  std::ifstream in(std::string(DRIVETWIN_SOURCE_DIR) + "/docs/run.md");
  ASSERT_TRUE(in) << "docs/run.md missing";
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string doc = ss.str();
  const std::string begin = "<!-- config-reference begin -->\n";
  const std::string end = "<!-- config-reference end -->";
  const auto b = doc.find(begin), e = doc.find(end);
  ASSERT_NE(b, std::string::npos);
  ASSERT_NE(e, std::string::npos);
  EXPECT_EQ(doc.substr(b + begin.size(), e - b - begin.size()), app::run::run_config_reference())
      << "regenerate with: drivetwin run --config-reference";
}

TEST(RunConfig, TheShippedConfigurationsLoadWithTheirBusFiles) {
  for (const char* name : {"twin-paper-2mw.toml", "twin-replay.toml"}) {
    const std::filesystem::path file =
        std::filesystem::path(DRIVETWIN_SOURCE_DIR) / "app/data/run" / name;
    const RunConfig c = app::run::load_run_config(file);
    EXPECT_NO_THROW((void)app::bus::load_bus_config(c.bus)) << name;
  }
}

}  // namespace
