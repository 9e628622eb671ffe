#pragma once
// The text log of the box: the real-time thread enqueues event codes with two numbers
// (no formatting, no allocation, no I/O); a non-real-time thread formats them into lines
// with a level (INFO/WARN/ERR), limited in rate per code (style.md §7, after ros2_control's
// RCLCPP_WARN_THROTTLE): at most one line per code per interval, the repeats counted and
// reported with the next line of that code.
//
// Events mark changes (a mode entered or left, an alarm raised), not states, so a steady
// fault costs one line, not one per cycle.
//
// Thread context: Event is plain; EventLog::format() on the non-RT log thread only.

#include <array>
#include <cstdint>
#include <cstdio>
#include <string>

namespace app::loop {

enum class EventCode : std::uint16_t {
  kStarted,              // a = cycle period [µs], b = ROM step [s]
  kScadaStale,           // a = hal::Status
  kScadaRecovered,       //
  kInputRejected,        // a = values rejected this cycle
  kHoldingInputs,        // b = held torque [N·m]
  kSteadyState,          // b = steady-state torque [N·m]
  kNoInputs,             //
  kInputsRecovered,      // a = TorqueSource
  kCmsGap,               // a = blocks lost
  kCmsFault,             // a = hal::Status of health()
  kCmsRecovered,         //
  kKeyphasorLost,        //
  kKeyphasorRecovered,   //
  kZoneChanged,          // a = point (0-based), b = VibrationZone
  kAlarmRaised,          // a = worst zone
  kAlarmCleared,         //
  kOverrun,              // a = periods skipped, b = lateness [µs]
  kRomAdopted,           // a = calibration generation, b = settle time [s]
  kCalibrationCheck,     // a = needs calibration (0/1), b = worst indicator / threshold
  kCalibrationDone,      // a = fits (0/1), b = worst indicator / threshold after
  kCalibrationSkipped,   // a = reason (1: CMS gap, 2: not steady, 3: no operating point)
  kCalibrationFailed,    // a = reason code
  kUnexplainedMismatch,  // a = generation, b = worst indicator / threshold left
  kDiagnosis,            // a = effects reported, b = the first one's confidence
  kQueueFull,            // a = which (0: snapshots, 1: windows)
  kStopped,              // a = cycles
  kCount
};
inline constexpr std::size_t kEventCodeCount = static_cast<std::size_t>(EventCode::kCount);

enum class EventLevel : std::uint8_t { kInfo, kWarn, kErr };

struct Event {
  std::int64_t stamp_ns = 0;  // [ns] loop time
  EventCode code = EventCode::kStarted;
  std::int32_t a = 0;
  double b = 0.0;
};

EventLevel level_of(EventCode code);
const char* name_of(EventCode code);

/// Formats events into lines, at most one per code (and per point, for per-point codes)
/// per interval.
class EventLog {
 public:
  /// @param interval_ns  minimum loop time between two lines of one code (0: every event)
  explicit EventLog(std::int64_t interval_ns) : interval_ns_(interval_ns) {}

  /// The line for `e`, or "" when it is suppressed (counted; the next line of its code
  /// says how many were).
  std::string format(const Event& e);

 private:
  static constexpr std::size_t kKeys = kEventCodeCount * 4;  // code × point (0..3)
  std::int64_t interval_ns_;
  std::array<std::int64_t, kKeys> last_ns_{};
  std::array<bool, kKeys> seen_{};
  std::array<std::uint64_t, kKeys> suppressed_{};
};

}  // namespace app::loop
