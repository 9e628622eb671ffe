#pragma once
// The loop's time: when each cycle runs and what time it is for the twin.
//
// Live (the box): CLOCK_MONOTONIC. Cycle k is due at t0 + k·T; the thread sleeps to that
// absolute deadline (clock_nanosleep(TIMER_ABSTIME)), so a late wake-up does not shift the
// later ones. A cycle that ends after the next deadline is an overrun: it is counted, the
// periods already missed are skipped (the next cycle is the first deadline still ahead;
// their time is not simulated and the count says so), and the loop goes on. The twin's
// time is the deadline of the cycle (what the period grid says, not when the thread woke).
// After ros2_control's sleep_for_periodic_cycle (controller_manager/src/sleeping_policies.cpp).
//
// Stepped (replay, simulation): the twin's time is k·T exactly — the recording supplies the
// clock, so a replay is deterministic whatever the machine does. With a pace factor s > 0
// the thread also sleeps to the wall-clock deadline wall0 + k·T/s (s = 1: real time), and a
// cycle finishing after it counts as an overrun (the replay falls behind) but skips
// nothing; with s = 0 ("--speed max") it never sleeps.
//
// Thread context: the RT thread only (after start()). No allocation; clock_nanosleep is
// the only blocking call, by design.

#include <cstdint>

#include "hal/clock.hpp"

namespace app::loop {

class CycleClock {
 public:
  enum class Mode : std::uint8_t { kLive, kStepped };

  struct Tick {
    hal::Timestamp now{0};      // [ns] the twin's time for this cycle
    double latency_us = 0.0;    // [µs] wake-up after the deadline (≥ 0)
    bool overran = false;       // the previous cycle ended after this deadline had passed
    std::uint64_t skipped = 0;  // [-] periods skipped before this cycle (live only)
  };

  /// @param pace stepped mode: recording seconds per wall second (0: as fast as possible)
  CycleClock(Mode mode, std::int64_t period_ns, double pace = 0.0);

  /// Starts the period grid now (first deadline: now); live, the twin's time counts from now.
  void start();
  /// Live: as start(), the twin's time counted from CLOCK_MONOTONIC `origin_ns` (the origin
  /// of the LoopTimeClock the bus backends stamp with, so both share one time base).
  void start(std::int64_t origin_ns);
  /// Sleeps to the next deadline (except stepped at pace 0) and returns the cycle's time.
  Tick wait();
  /// Compute time of the cycle that just ended [µs] (wall clock since its wake-up).
  double cycle_time_us() const;

  std::int64_t period_ns() const { return period_ns_; }

  /// CLOCK_MONOTONIC [ns].
  static std::int64_t monotonic_ns();

 private:
  Mode mode_;
  std::int64_t period_ns_;
  double pace_;
  std::int64_t t0_wall_ns_ = 0;    // [ns] CLOCK_MONOTONIC at start()
  std::int64_t origin_ns_ = 0;     // [ns] CLOCK_MONOTONIC of the live twin's time 0
  std::int64_t next_wall_ns_ = 0;  // [ns] next wall deadline
  std::int64_t woke_wall_ns_ = 0;  // [ns] when the current cycle woke
  std::int64_t cycle_ = 0;         // [-] index of the next cycle (stepped)
  std::int64_t twin_ns_ = 0;       // [ns] twin time of the next cycle
};

/// The live twin's time as a hal::Clock: CLOCK_MONOTONIC minus the origin the CycleClock
/// counts from (CycleClock::start(origin_ns)). The bus backends stamp with it, so SCADA ages,
/// CMS block and keyphasor stamps are on the time base of the loop's `now`.
class LoopTimeClock final : public hal::Clock {
 public:
  explicit LoopTimeClock(std::int64_t origin_ns) : origin_ns_(origin_ns) {}
  hal::Timestamp now() const override {
    return hal::Timestamp{CycleClock::monotonic_ns() - origin_ns_};
  }
  std::int64_t origin_ns() const { return origin_ns_; }

 private:
  std::int64_t origin_ns_;
};

}  // namespace app::loop
