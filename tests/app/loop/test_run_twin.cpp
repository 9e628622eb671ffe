// `drivetwin run` end to end on the simulated and replayed buses (app/loop/runner.hpp):
// the loop keeps its period, accumulates, publishes and stops cleanly; a replay runs on the
// recording's clock, so it covers exactly the rows' time and repeats bit for bit.
// Short runs at a low ROM rate: these also run under qemu-aarch64 and the sanitizers.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "loop/runner.hpp"
#include "loop/twin.hpp"
#include "model/dynamics/rom.hpp"
#include "run/run_config.hpp"
#include "run_test_util.hpp"

namespace {

using run_test::TempDir;
using run_test::write;

constexpr const char* kSimBus =
    "format = \"drivetwin-bus/1\"\n[scada]\nbackend = \"sim\"\n[cms]\nbackend = \"sim\"\n"
    "[keyphasor]\nbackend = \"sim\"\n[outputs]\nbackend = \"memory\"\n";
constexpr const char* kReplayBus = "format = \"drivetwin-bus/1\"\n[scada]\nbackend = \"none\"\n";

// A run file at a low ROM rate (15.625 ms × steps), normal-priority threads.
std::string run_file(const std::string& bus, bool calibration, int steps) {
  std::ostringstream s;
  s << "format = \"drivetwin-run/1\"\n[twin]\nbus = \"" << bus << "\"\n"
    << "[loop]\nperiod_us = 15625\nrom_steps_per_cycle = " << steps
    << "\nrom_cutoff_hz = " << (steps >= 16 ? 150.0 : 60.0) << "\npublish_divisor = 64\n"
    << "[calibration]\nenabled = " << (calibration ? "true" : "false") << "\n"
    << "[threads.rt_loop]\npolicy = \"other\"\npriority = 0\n";
  return s.str();
}

app::run::RunConfig config(const TempDir& dir, const std::string& bus_text, bool calibration,
                           int steps = 16) {
  write(dir.path / "bus.toml", bus_text);
  write(dir.path / "twin.toml", run_file("bus.toml", calibration, steps));
  app::run::RunConfig c = app::run::load_run_config(dir.path / "twin.toml");
  c.state_dir = (dir.path / "state").string();
  return c;
}

TEST(RunTwin, OnSimulatedBusesEveryPeriodRunsAndDamageAccumulates) {
  // Arrange
  TempDir dir("dt-run-sim");
  const app::run::RunConfig c = config(dir, kSimBus, false);
  std::ostringstream log;
  app::loop::RunOptions o;
  o.duration_s = 2.0;
  o.log = &log;
  // Act
  const app::loop::RunSummary s = app::loop::run_twin(c, o);
  // Assert: 2 s / 15.625 ms = 128 cycles of 16 steps; the paper point's torque loads every
  // gear contact channel; the results say running and where the torque came from.
  EXPECT_EQ(s.last.counters.cycles, 128u) << log.str();
  EXPECT_EQ(s.last.counters.rom_steps, 128u * 16u);
  EXPECT_EQ(s.last.counters.overruns, 0u);
  EXPECT_GT(s.last.counters.cms_blocks, 0u);
  EXPECT_TRUE(s.last.status_word & app::results::kStatusRunning);
  EXPECT_EQ(s.last.torque_source, app::loop::TorqueSource::kMeasuredTorque);
  EXPECT_NEAR(s.elapsed_s, 2.0, 1e-9);
  ASSERT_FALSE(s.damage.empty());
  EXPECT_GT(s.damage[0], 0.0);  // sun contact
  EXPECT_NE(log.str().find("INFO started"), std::string::npos) << log.str();
  // The state was saved at the end and is restored by the next run.
  EXPECT_TRUE(std::filesystem::exists(dir.path / "state" / "twin-state.a") ||
              std::filesystem::exists(dir.path / "state" / "twin-state.b"));
  EXPECT_TRUE(std::filesystem::exists(dir.path / "state" / "trends.db"));
  const app::loop::RunSummary again = app::loop::run_twin(c, o);
  EXPECT_TRUE(again.restored);
  EXPECT_NEAR(again.elapsed_s, 4.0, 1e-9);
  EXPECT_NEAR(again.damage[0], 2.0 * s.damage[0], 1e-9 * s.damage[0]);
}

TEST(RunTwin, AReplayCoversItsRowsExactlyAndRepeatsBitForBit) {
  // Arrange: the built-in day's first two 10-minute rows, the first minute replayed
  // (--duration), the ROM at 1024 Hz (cut-off 150 Hz: stable since the modes the step cannot
  // resolve are quasi-static, model/dynamics/rom.hpp "Stability").
  TempDir dir("dt-run-replay");
  write(dir.path / "day.csv", run_test::builtin_day_rows(2));
  app::run::RunConfig c = config(dir, kReplayBus, false, 16);
  app::loop::RunOptions o;
  o.replay = (dir.path / "day.csv").string();
  o.duration_s = 60.0;
  std::ostringstream log;
  o.log = &log;
  std::uint32_t faults = 0;
  o.on_cycle = [&](const app::loop::Twin& twin, hal::Timestamp) {
    faults |= twin.last_snapshot().fault_word;
  };
  // Act: two runs from an empty state each.
  const app::loop::RunSummary a = app::loop::run_twin(c, o);
  c.state_dir = (dir.path / "state2").string();
  const app::loop::RunSummary b = app::loop::run_twin(c, o);
  // Assert: the 60 s, every step valid; the rotor turned rpm × 1 min (13.79819973 rpm in
  // the file), to the accumulator's rounding of 2^-33 rev per step (damage_accumulator.hpp).
  EXPECT_DOUBLE_EQ(a.elapsed_s, 60.0) << log.str();
  const double steps = 60.0 * 1024.0;
  EXPECT_NEAR(a.last.rotor_revolutions, 13.79819973 * 1.0, steps * std::ldexp(1.0, -33));
  EXPECT_EQ(a.last.torque_source, app::loop::TorqueSource::kPower);
  ASSERT_EQ(a.damage.size(), b.damage.size());
  for (std::size_t i = 0; i < a.damage.size(); ++i)
    EXPECT_EQ(a.damage[i], b.damage[i]) << a.channel_names[i];  // bit for bit
  EXPECT_GT(a.damage[0], 0.0);
  EXPECT_EQ(faults & app::supervisor::kFaultRomDiverged, 0u) << log.str();  // every step counted
}

// The replay against `drivetwin damage` runs natively only (test_replay_damage.cpp, 3 rows at
// 4096 Hz, the rate `damage --spectrum dynamics-rows` is compared at).

TEST(RunTwin, ADivergingRomRaisesAFaultAndLeavesTheDamageFinite) {
  // Arrange: a ROM broken on purpose (no ROM the builder makes is known to diverge): its
  // lowest mode's propagator scaled by 1.01 per step at 1024 Hz, against the 0.24 % its
  // damping takes back (η = 5 1/s: e^{-η·Δt/2}), so that its loads leave any gearbox's within
  // a second or two of every restart.
  TempDir dir("dt-run-diverge");
  write(dir.path / "day.csv", run_test::builtin_day_rows(2));
  app::run::RunConfig c = config(dir, kReplayBus, false, 16);
  app::loop::RunOptions o;
  o.replay = (dir.path / "day.csv").string();
  o.duration_s = 60.0;
  o.on_rom_built = [](model::dynamics::RomData& rom) {
    for (double* p : {&rom.pqq[0], &rom.pqv[0], &rom.pvq[0], &rom.pvv[0]}) *p *= 1.01;
  };
  std::ostringstream log;
  o.log = &log;
  std::uint32_t faults = 0;
  o.on_cycle = [&](const app::loop::Twin& twin, hal::Timestamp) {
    faults |= twin.last_snapshot().fault_word;
  };
  // Act
  const app::loop::RunSummary s = app::loop::run_twin(c, o);
  // Assert: the minute is run, the fault is said, and no NaN or absurd load reached
  // the lifetime damage (finite and below what one minute of rated load could give a gear).
  // The counted time is the minute less the cycles cut short by a divergence.
  EXPECT_LE(s.elapsed_s, 60.0) << log.str();
  EXPECT_GT(s.elapsed_s, 30.0) << log.str();
  EXPECT_NE(faults & app::supervisor::kFaultRomDiverged, 0u);
  ASSERT_FALSE(s.damage.empty());
  for (std::size_t i = 0; i < s.damage.size(); ++i) {
    EXPECT_TRUE(std::isfinite(s.damage[i])) << s.channel_names[i];
    EXPECT_GE(s.damage[i], 0.0) << s.channel_names[i];
    EXPECT_LT(s.damage[i], 1e-3) << s.channel_names[i];
  }
}

TEST(RunTwin, StartUpErrorsNameWhatIsWrong) {
  TempDir dir("dt-run-bad");
  app::run::RunConfig c = config(dir, kReplayBus, false);
  app::loop::RunOptions o;
  std::ostringstream log;
  o.log = &log;
  try {
    (void)app::loop::run_twin(c, o);
    FAIL() << "a twin without a SCADA source must not start";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("needs a SCADA source"), std::string::npos) << e.what();
  }
  o.replay = (dir.path / "missing.csv").string();
  try {
    (void)app::loop::run_twin(c, o);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("missing.csv"), std::string::npos) << e.what();
  }
}

}  // namespace
