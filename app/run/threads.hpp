#pragma once
// The one table of the box's threads: name, scheduling policy and priority, CPU and stack
// size of every thread `drivetwin run` starts — the real-time loop, the calibration
// thread, the bus I/O threads (handed to the hal backends' `thread` members) and the
// non-real-time workers. The constexpr values below are the defaults; the run
// configuration may override each field (`threads.<key>.policy|priority|cpu|stack_kib`,
// run_config.hpp), and the result is the one table every thread is started from.
//
// Priorities (SCHED_FIFO 1..99; the kernel's own threaded IRQs run at 50): the RT loop is
// highest because a cycle is short (tens of µs) and sets the twin's timing; the CAN and
// GPIO receive threads next, so that frames and edges are taken off the sockets before
// their kernel buffers fill; the Modbus poller below the IRQ threads (it polls at 1 Hz and
// its timeouts are its own); everything that writes files or talks to clients at normal
// priority; the calibration at SCHED_IDLE, so that it only ever runs on idle CPU time.
//
// Thread context: constants; read at start-up.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "hal/thread.hpp"

namespace app::run {

enum class ThreadId : std::uint8_t {
  kRtLoop,
  kCalibration,
  kScadaIo,
  kCmsIo,
  kKeyphasorIo,
  kResultsServer,
  kPersistence,
  kTrends,
  kLog,
  kCount
};
inline constexpr std::size_t kThreadCount = static_cast<std::size_t>(ThreadId::kCount);
using ThreadTable = std::array<hal::ThreadAttributes, kThreadCount>;

inline constexpr std::size_t kKiB = 1024;

/// Config keys of the threads (threads.<key>.*), in ThreadId order.
inline constexpr std::array<std::string_view, kThreadCount> kThreadKeys{
    "rt_loop",        "calibration", "scada_io", "cms_io", "keyphasor_io",
    "results_server", "persistence", "trends",   "log"};

/// The defaults (name ≤ 15 characters: what `ps -L` and `top -H` show).
inline constexpr ThreadTable kDefaultThreads{{
    {"dt-rt", hal::SchedPolicy::kFifo, 80, -1, 256 * kKiB},
    {"dt-calib", hal::SchedPolicy::kIdle, 0, -1, 1024 * kKiB},
    {"dt-scada", hal::SchedPolicy::kFifo, 40, -1, 128 * kKiB},
    {"dt-cms", hal::SchedPolicy::kFifo, 70, -1, 128 * kKiB},
    {"dt-keyphasor", hal::SchedPolicy::kFifo, 70, -1, 128 * kKiB},
    {"dt-results", hal::SchedPolicy::kOther, 0, -1, 256 * kKiB},
    {"dt-persist", hal::SchedPolicy::kOther, 5, -1, 256 * kKiB},
    {"dt-trends", hal::SchedPolicy::kOther, 10, -1, 512 * kKiB},
    {"dt-log", hal::SchedPolicy::kOther, 10, -1, 128 * kKiB},
}};

}  // namespace app::run
