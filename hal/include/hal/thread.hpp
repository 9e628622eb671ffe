#pragma once
// Threads with explicit attributes: name, scheduling policy and priority, CPU
// affinity and stack size, so that one constexpr table in app/ can say how every
// thread of the box runs (style.md §2, §4) and the backends' I/O threads follow it.
//
// What is applied where:
//   stack size      pthread_attr_setstacksize() at creation (rounded up to whole pages,
//                   at least PTHREAD_STACK_MIN); 0 keeps the system default.
//   name            pthread_setname_np() in the new thread (≤ 15 characters, longer
//                   names are cut; shows in `ps -L`, `top -H`, gdb).
//   CPU affinity    pthread_setaffinity_np() in the new thread (cpu ≥ 0).
//   policy/priority pthread_setschedparam() (kFifo, kRoundRobin: priority 1..99;
//                   kIdle: SCHED_IDLE) or setpriority() on the thread id (kOther, kBatch:
//                   priority is the nice value −20..19) in the new thread.
// A step the OS refuses (typically EPERM for SCHED_FIFO without CAP_SYS_NICE or an
// RLIMIT_RTPRIO, EINVAL for a CPU that does not exist) does not stop the thread: it
// runs with what was granted — for a refused real-time policy, SCHED_OTHER at nice 0 —
// and ThreadReport says which steps failed and why, for the caller to warn about.
// start() returns only after the new thread has applied its attributes.
//
// Thread context: start() and join() from a non-real-time (control) thread: they
// allocate and block. The started function runs on the new thread.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "hal/status.hpp"

namespace hal {

enum class SchedPolicy : std::uint8_t {
  kOther,       // SCHED_OTHER, priority = nice value
  kBatch,       // SCHED_BATCH, priority = nice value
  kIdle,        // SCHED_IDLE (below nice 19), priority ignored
  kFifo,        // SCHED_FIFO, priority 1..99
  kRoundRobin,  // SCHED_RR, priority 1..99
};
const char* to_string(SchedPolicy policy);

/// How one thread runs. A literal type: app/ keeps its table of them constexpr.
struct ThreadAttributes {
  const char* name = "drivetwin";  // ≤ 15 characters shown by the OS
  SchedPolicy policy = SchedPolicy::kOther;
  int priority = 0;             // FIFO/RR: 1..99; OTHER/BATCH: nice −20..19; IDLE: unused
  int cpu = -1;                 // CPU to pin to; −1 = any
  std::size_t stack_bytes = 0;  // [B] 0 = the system default
};

/// Checks ranges (priority for the policy, cpu ≥ −1, stack 0 or ≥ 16 KiB, name non-empty).
/// @return empty when good, else what is wrong (names the field).
std::string validate(const ThreadAttributes& attributes);

/// What the OS granted when the thread started.
struct ThreadReport {
  bool started = false;
  bool name_applied = false;
  bool affinity_applied = true;  // true when no CPU was asked for
  bool policy_applied = false;   // false: running SCHED_OTHER at nice 0 instead
  int policy_errno = 0;          // errno of the refused scheduling step (0 if none)
  int affinity_errno = 0;
  std::size_t stack_bytes = 0;  // [B] the stack size in effect (0: system default)
  /// One line naming the thread, what was asked and what was refused; empty when all applied.
  std::string warning;
};

class Thread {
 public:
  Thread();
  ~Thread();  // joins if still running (the function must have been told to return)
  Thread(const Thread&) = delete;
  Thread& operator=(const Thread&) = delete;

  /// Creates the thread with `attributes` and runs `body` on it.
  /// @return kOk (see report() for what was granted), kInvalidConfig (validate() failed,
  ///         nothing started), kIoError (pthread_create failed), kWrongState (running).
  Status start(const ThreadAttributes& attributes, std::function<void()> body);
  /// Waits for the function to return. No-op when not started.
  void join();
  bool joinable() const { return impl_ != nullptr; }
  const ThreadReport& report() const { return report_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  ThreadReport report_;
};

}  // namespace hal
