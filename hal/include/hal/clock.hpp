#pragma once
// Time source of the loop. Components never read a clock: the loop asks the
// Clock once per cycle and passes `now` in. The monotonic clock is for the
// nacelle box; a replay sets the clock from the recording (ManualClock), so a
// replay and a QEMU run are deterministic.
//
// Thread context: now() is called from the RT thread; it must not block or
// allocate. ManualClock::set/advance are called by the replay driver on the
// same thread (or before the loop starts).

#include <atomic>
#include <chrono>
#include <cstdint>

namespace hal {

/// Time stamps on every hal interface: nanoseconds since the clock's epoch
/// (CLOCK_MONOTONIC for hardware; the start of the recording for a replay).
using Timestamp = std::chrono::nanoseconds;

class Clock {
 public:
  virtual ~Clock() = default;
  /// @return current time [ns since epoch]. Non-blocking, allocation-free.
  virtual Timestamp now() const = 0;
};

/// CLOCK_MONOTONIC through std::chrono::steady_clock (the same clock the kernel
/// stamps GPIO edge events and SocketCAN frames with on Linux).
class MonotonicClock final : public Clock {
 public:
  Timestamp now() const override {
    return std::chrono::duration_cast<Timestamp>(
        std::chrono::steady_clock::now().time_since_epoch());
  }
};

/// A clock driven from outside: replays and tests. Lock-free; set/advance from
/// one thread, now() from any.
class ManualClock final : public Clock {
 public:
  explicit ManualClock(Timestamp start = Timestamp{0}) : now_ns_(start.count()) {}
  Timestamp now() const override { return Timestamp{now_ns_.load(std::memory_order_acquire)}; }
  void set(Timestamp t) { now_ns_.store(t.count(), std::memory_order_release); }
  void advance(Timestamp dt) { now_ns_.fetch_add(dt.count(), std::memory_order_acq_rel); }

 private:
  std::atomic<std::int64_t> now_ns_;
};

}  // namespace hal
