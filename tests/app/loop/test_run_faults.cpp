// Fault injection through `drivetwin run` on the simulated buses (issue 13): SCADA silent,
// NaN and absurd values; CMS gaps, garbage and bus-off; keyphasor silent; the state folder
// full and gone — injected into the running twin's own backends at set loop times, and
// cleared again. The loop keeps its period (a cycle every period, the ROM stepped
// throughout), the right status and fault bits are set while a fault lasts, and everything
// clears when it ends. The loop runs on the simulated buses' stepped clock (deterministic);
// the persistence faults are paced (the persistence thread works in wall time).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <sstream>
#include <vector>

#include "hal/sim_backends.hpp"
#include "loop/runner.hpp"
#include "loop/twin.hpp"
#include "run/run_config.hpp"
#include "run_test_util.hpp"
#include "supervisor/supervisor.hpp"

namespace {

namespace fs = std::filesystem;
using app::loop::Snapshot;
using app::loop::TorqueSource;
using hal::SimFault;
using run_test::TempDir;
using run_test::write;
namespace sup = app::supervisor;
namespace res = app::results;

constexpr double kPeriod_s = 0.015625;

app::run::RunConfig config(const TempDir& dir, const std::string& extra = "") {
  write(dir.path / "bus.toml",
        "format = \"drivetwin-bus/1\"\n[scada]\nbackend = \"sim\"\n[cms]\nbackend = \"sim\"\n"
        "[keyphasor]\nbackend = \"sim\"\n[outputs]\nbackend = \"memory\"\n");
  std::ostringstream s;
  s << "format = \"drivetwin-run/1\"\n[twin]\nbus = \"bus.toml\"\n"
    << "[loop]\nperiod_us = 15625\nrom_steps_per_cycle = 16\nrom_cutoff_hz = 150.0\n"
    << "publish_divisor = 16\n[inputs]\nscada_hold_s = 3.0\n[calibration]\nenabled = false\n"
    << extra << "[threads.rt_loop]\npolicy = \"other\"\npriority = 0\n";
  write(dir.path / "twin.toml", s.str());
  app::run::RunConfig c = app::run::load_run_config(dir.path / "twin.toml");
  c.state_dir = (dir.path / "state").string();
  return c;
}

// What the RT thread saw at every publish (preallocated; the hook is real-time safe).
struct Record {
  double t = 0.0;
  std::uint16_t status = 0, fault = 0;
  TorqueSource source = TorqueSource::kNone;
  double elapsed_s = 0.0;
  std::uint64_t cycles = 0, rejected = 0;
};
struct Recorder {
  std::vector<Record> rows;
  std::uint32_t last_sequence = 0;
  explicit Recorder(std::size_t n) { rows.reserve(n); }
  void on_cycle(const app::loop::Twin& twin, hal::Timestamp) {
    const Snapshot& s = twin.last_snapshot();
    if (s.sequence == last_sequence || rows.size() == rows.capacity()) return;
    last_sequence = s.sequence;
    rows.push_back({1e-9 * static_cast<double>(s.stamp_ns), s.status_word, s.fault_word,
                    s.torque_source, twin.accumulator().elapsed_s(), s.counters.cycles,
                    s.counters.rejected_inputs});
  }
  bool any(double t0, double t1, const std::function<bool(const Record&)>& p) const {
    for (const Record& r : rows)
      if (r.t >= t0 && r.t < t1 && p(r)) return true;
    return false;
  }
  bool all(double t0, double t1, const std::function<bool(const Record&)>& p) const {
    bool seen = false;
    for (const Record& r : rows) {
      if (r.t < t0 || r.t >= t1) continue;
      seen = true;
      if (!p(r)) return false;
    }
    return seen;
  }
  const Record& at(double t) const {
    const Record* best = &rows.front();
    for (const Record& r : rows)
      if (r.t <= t) best = &r;
    return *best;
  }
};

// A fault injected over [from, to) of loop time into one backend.
struct Injection {
  double from, to;
  int bus;  // 0 SCADA, 1 CMS, 2 keyphasor
  SimFault fault;
};

bool bit(std::uint16_t w, std::uint16_t b) { return (w & b) != 0; }

TEST(RunFaults, BusFaultsSetTheirBitsWhileTheyLastAndClearAfterwardsAndTheLoopKeepsItsPeriod) {
  // Arrange: 8 s of each fault, 8 s of recovery after each.
  TempDir dir("dt-faults");
  const app::run::RunConfig c = config(dir);
  const std::vector<Injection> plan{
      {8, 16, 0, SimFault::kSilent},      {24, 32, 0, SimFault::kNonFinite},
      {40, 48, 0, SimFault::kOutOfRange}, {56, 64, 1, SimFault::kGaps},
      {72, 80, 1, SimFault::kGarbage},    {88, 96, 1, SimFault::kBusOff},
      {104, 112, 2, SimFault::kSilent}};
  constexpr double kEnd = 120.0;
  hal::SimScadaSource* scada = nullptr;
  hal::SimCmsStream* cms = nullptr;
  hal::SimKeyphasor* keyphasor = nullptr;
  Recorder rec(static_cast<std::size_t>(kEnd / (16 * kPeriod_s)) + 16);
  std::size_t next = 0;
  bool active = false;
  app::loop::RunOptions o;
  o.duration_s = kEnd;
  std::ostringstream log;
  o.log = &log;
  o.on_devices = [&](const app::loop::TwinDevices& d) {
    scada = dynamic_cast<hal::SimScadaSource*>(d.scada);
    cms = dynamic_cast<hal::SimCmsStream*>(d.cms);
    keyphasor = dynamic_cast<hal::SimKeyphasor*>(d.keyphasor);
  };
  o.on_cycle = [&](const app::loop::Twin& twin, hal::Timestamp now) {
    const double t = 1e-9 * static_cast<double>(now.count());
    if (next < plan.size()) {
      const Injection& in = plan[next];
      const SimFault f = !active && t >= in.from ? in.fault : SimFault::kNone;
      if ((!active && t >= in.from) || (active && t >= in.to)) {
        if (in.bus == 0) scada->inject(f);
        if (in.bus == 1) cms->inject(f);
        if (in.bus == 2) keyphasor->inject(f);
        if (active) ++next;
        active = !active;
      }
    }
    rec.on_cycle(twin, now);
  };
  // Act
  const app::loop::RunSummary s = app::loop::run_twin(c, o);
  // Assert: the loop kept its period and stepped the model throughout.
  ASSERT_TRUE(scada && cms && keyphasor);
  EXPECT_EQ(s.last.counters.cycles, static_cast<std::uint64_t>(std::llround(kEnd / kPeriod_s)));
  EXPECT_NEAR(s.elapsed_s, kEnd, 1e-6) << "the ROM was not stepped in every cycle";
  EXPECT_TRUE(rec.all(4, 8, [](const Record& r) {
    return bit(r.status, res::kStatusRunning) && !bit(r.status, res::kStatusDegraded) &&
           r.fault == 0 && r.source == TorqueSource::kMeasuredTorque;
  })) << log.str();
  // SCADA silent: stale, held, then the steady state; the model still driven.
  EXPECT_TRUE(rec.any(8, 16, [](const Record& r) {
    return bit(r.status, res::kStatusScadaStale) && bit(r.status, res::kStatusDegraded) &&
           bit(r.fault, sup::kFaultScadaStale) && bit(r.fault, sup::kFaultHoldingInputs) &&
           r.source == TorqueSource::kHeld;
  }));
  EXPECT_TRUE(rec.any(8, 16, [](const Record& r) {
    return bit(r.fault, sup::kFaultSteadyState) && r.source == TorqueSource::kSteadyState;
  }));
  // NaN and ×1000: rejected (counted), the inputs held.
  for (const double from : {24.0, 40.0}) {
    EXPECT_TRUE(rec.any(from, from + 8, [](const Record& r) {
      return bit(r.fault, sup::kFaultInputRejected) && bit(r.status, res::kStatusDegraded) &&
             r.source != TorqueSource::kMeasuredTorque;
    })) << from;
    EXPECT_GT(rec.at(from + 7.5).rejected, rec.at(from).rejected) << from;
  }
  // CMS gaps, garbage, bus-off: the CMS status bit, the gap or fault bit.
  EXPECT_TRUE(rec.any(56, 64, [](const Record& r) {
    return bit(r.status, res::kStatusCmsFault) && bit(r.fault, sup::kFaultCmsGap);
  }));
  for (const double from : {72.0, 88.0}) {
    EXPECT_TRUE(rec.any(from, from + 8, [](const Record& r) {
      return bit(r.status, res::kStatusCmsFault) && bit(r.fault, sup::kFaultCmsBusOff);
    })) << from;
  }
  // Keyphasor silent.
  EXPECT_TRUE(rec.any(104, 112, [](const Record& r) {
    return bit(r.status, res::kStatusKeyphasorFault) && bit(r.fault, sup::kFaultKeyphasor);
  }));
  // Every fault cleared: the last 4 s of each recovery window, and the end, as at the start.
  for (const Injection& in : plan) {
    EXPECT_TRUE(rec.all(in.to + 4, in.to + 8,
                        [](const Record& r) {
                          return r.fault == 0 && !bit(r.status, res::kStatusDegraded) &&
                                 r.source == TorqueSource::kMeasuredTorque;
                        }))
        << "after the fault of " << in.from << " s: fault word " << rec.at(in.to + 7).fault
        << ", status " << rec.at(in.to + 7).status;
    // and the damage went on accumulating during the fault
    EXPECT_GT(rec.at(in.to).elapsed_s, rec.at(in.from).elapsed_s + 0.9 * (in.to - in.from - 1));
  }
}

TEST(RunFaults, AFullOrVanishedStateFolderSetsThePersistenceBitUntilASaveSucceedsAgain) {
  // Arrange: checkpoints every 2 s of loop time, paced at 20× real time; the state folder
  // "full" over [10, 30) s (RLIMIT_FSIZE below a record's size: writes fail with EFBIG, as on
  // a full disk; no privileges needed) and replaced by a plain file over [40, 50) s (every
  // open in it fails — as root, permission bits would not stop the twin, so a read-only
  // folder is represented by the same failure path).
  TempDir dir("dt-state-faults");
  const app::run::RunConfig c = config(dir, "[persistence]\ncheckpoint_interval_s = 2.0\n");
  const fs::path state = c.state_dir;
  const fs::path moved = state.string() + ".moved";
  rlimit saved_limit{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &saved_limit), 0);
  const auto old_handler = ::signal(SIGXFSZ, SIG_IGN);
  constexpr double kEnd = 60.0;
  Recorder rec(static_cast<std::size_t>(kEnd / (16 * kPeriod_s)) + 16);
  int stage = 0;
  app::loop::RunOptions o;
  o.duration_s = kEnd;
  o.speed = 20.0;
  std::ostringstream log;
  o.log = &log;
  o.on_cycle = [&](const app::loop::Twin& twin, hal::Timestamp now) {
    const double t = 1e-9 * static_cast<double>(now.count());
    // (Test-only file operations on the RT thread: the loop is paced with room to spare.)
    if (stage == 0 && t >= 10.0) {
      rlimit small = saved_limit;
      small.rlim_cur = 16 * 1024;
      (void)setrlimit(RLIMIT_FSIZE, &small);
      ++stage;
    } else if (stage == 1 && t >= 30.0) {
      (void)setrlimit(RLIMIT_FSIZE, &saved_limit);
      ++stage;
    } else if (stage == 2 && t >= 40.0) {
      std::error_code ec;
      fs::rename(state, moved, ec);
      write(state, "not a folder\n");
      ++stage;
    } else if (stage == 3 && t >= 50.0) {
      std::error_code ec;
      fs::remove(state, ec);
      fs::rename(moved, state, ec);
      ++stage;
    }
    rec.on_cycle(twin, now);
  };
  // Act
  const app::loop::RunSummary s = app::loop::run_twin(c, o);
  (void)setrlimit(RLIMIT_FSIZE, &saved_limit);
  ::signal(SIGXFSZ, old_handler);
  // Assert
  EXPECT_EQ(s.last.counters.cycles, static_cast<std::uint64_t>(std::llround(kEnd / kPeriod_s)));
  EXPECT_TRUE(
      rec.all(4, 10, [](const Record& r) { return !bit(r.fault, sup::kFaultPersistence); }));
  EXPECT_TRUE(rec.any(10, 30, [](const Record& r) { return bit(r.fault, sup::kFaultPersistence); }))
      << log.str();
  EXPECT_TRUE(rec.all(36, 40, [](const Record& r) {
    return !bit(r.fault, sup::kFaultPersistence);
  })) << log.str();
  EXPECT_TRUE(rec.any(40, 50, [](const Record& r) { return bit(r.fault, sup::kFaultPersistence); }))
      << log.str();
  EXPECT_TRUE(rec.all(56, 60, [](const Record& r) {
    return !bit(r.fault, sup::kFaultPersistence);
  })) << log.str();
  EXPECT_NE(log.str().find("WARN: checkpoint"), std::string::npos) << log.str();
  EXPECT_NE(log.str().find("checkpoint saved again"), std::string::npos) << log.str();
  // The state folder is whole again and holds the end of the run.
  EXPECT_NEAR(s.elapsed_s, kEnd, 1e-6);
  EXPECT_TRUE(fs::exists(state / "twin-state.a") || fs::exists(state / "twin-state.b"));
}

}  // namespace
