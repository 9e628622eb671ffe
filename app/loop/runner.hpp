#pragma once
// `drivetwin run`'s composition: from a validated run configuration to a running twin and
// back (style.md §2):
//
//   main (non-RT): load the drivetrain, the bus wiring and the persisted state (damage,
//     calibrated parameters) → build the ROM → construct every object once (devices, the
//     Twin, mailboxes, calibration windows, checkpoint buffers) → configure and activate the
//     devices (their I/O threads start with the thread table's attributes) → lock memory
//     (mlockall; a refusal is a warning) → start the threads:
//   RT loop      the cycle (twin.hpp) at the configured period and priority
//   calibration  compares the model with CMS windows and recalibrates (calibration_worker.hpp)
//   service      the text log (events → lines, rate-limited), the RUL rate history
//   persistence  damage checkpoints saved crash-safely every checkpoint interval
//   → wait for the end (SIGTERM/SIGINT, the end of a replay, or --duration) → stop the RT
//     loop → save a final checkpoint → stop the others → deactivate the devices (outputs
//     to their safe states).
//
// --replay swaps the SCADA source (and, for a recording bundle, the CMS stream and the
// keyphasor) for the replay backends; the loop then runs on the recording's clock
// (stepped, deterministic), as fast as it can (--speed max) or paced.
//
// Thread context: run_twin() on the main thread; it starts and joins the others.

#include <atomic>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "hal/clock.hpp"
#include "loop/snapshot.hpp"
#include "run/run_config.hpp"

namespace model::dynamics {
struct RomData;
}

namespace app::loop {

class Twin;
struct TwinDevices;
class TimingHistogram;

struct RunOptions {
  std::string replay;  // "" (live buses), a recording bundle folder, a SCADA CSV or builtin:NAME
  double speed = 0.0;  // replay and simulated buses: recording seconds per wall second;
                       // 0 = as fast as possible
  double duration_s =
      0.0;  // [s] stop after this much loop time (0: the end of the replay, or a signal)
  bool print_config = false;  // log the effective configuration at start
  /// Replay / simulated buses: before each cycle, wait while the calibration thread holds a
  /// window, so that a calibrated model arrives at a cycle that does not depend on the
  /// machine: the whole run, calibration included, repeats bit for bit.
  bool lockstep = false;
  std::ostream* log = nullptr;  // where log lines go (nullptr: stderr)
  /// Test hook: called on the RT thread once, after its set-up and before the first cycle.
  std::function<void()> on_rt_start;
  /// Test hook: called on the RT thread once after the last cycle.
  std::function<void()> on_rt_stop;
  /// Test hook (fault injection): called once on the starting thread with the devices,
  /// after they are active and before the loop's threads start.
  std::function<void(const TwinDevices&)> on_devices;
  /// Test hook (fault injection): called once on the starting thread with the reduced-order
  /// model just built, before the twin is constructed (a test breaks it on purpose).
  std::function<void(model::dynamics::RomData&)> on_rom_built;
  /// Test hook: called on the RT thread after every cycle with the twin (its accumulator,
  /// counters, last snapshot) and the cycle's loop time; must be real-time safe.
  std::function<void(const Twin&, hal::Timestamp)> on_cycle;
  /// The timing benchmark's histogram of every cycle's wake-up latency and cycle time
  /// (nullptr: not recorded); filled on the RT thread.
  TimingHistogram* timing = nullptr;
  /// Simulated buses on the live clock (the timing benchmark): the cabinet's schedule —
  /// absolute deadlines on CLOCK_MONOTONIC, missed periods skipped — instead of the
  /// simulation's stepped time paced at `speed`. Ignored for a replay.
  bool live_clock = false;
  /// Set from outside (signal handler, test) to end the run; polled every cycle.
  std::atomic<bool>* stop = nullptr;
};

struct RunSummary {
  std::vector<std::string> channel_names;  // "component/detail/mode" per damage channel
  std::vector<double> damage;              // [-] per channel, lifetime (incl. restored)
  double elapsed_s = 0.0;                  // [s] accumulated into the damage (lifetime)
  double loop_time_s = 0.0;                // [s] loop time this run covered
  double wall_time_s = 0.0;                // [s]
  Snapshot last{};                         // the final snapshot
  std::string rt_thread_warning;           // what the OS refused the RT thread ("" if nothing)
  bool memory_locked = false;
  std::uint32_t calibration_generation = 0;
  bool restored = false;  // damage was loaded from the state folder
  double rt_cpu_s = 0.0;  // [s] CPU time the RT thread used (CLOCK_THREAD_CPUTIME_ID)
};

/// Runs the twin until it is told to stop. Throws std::runtime_error (with a message
/// naming what and where) when start-up fails; never during the run.
RunSummary run_twin(const run::RunConfig& config, const RunOptions& options);

}  // namespace app::loop
