#include "loop/events.hpp"

#include <cinttypes>

#include "hal/status.hpp"
#include "loop/snapshot.hpp"

namespace app::loop {

EventLevel level_of(EventCode code) {
  switch (code) {
    case EventCode::kStarted:
    case EventCode::kScadaRecovered:
    case EventCode::kInputsRecovered:
    case EventCode::kCmsRecovered:
    case EventCode::kKeyphasorRecovered:
    case EventCode::kZoneChanged:
    case EventCode::kAlarmCleared:
    case EventCode::kRomAdopted:
    case EventCode::kCalibrationCheck:
    case EventCode::kCalibrationDone:
    case EventCode::kCalibrationSkipped:
    case EventCode::kStopped:
      return EventLevel::kInfo;
    case EventCode::kAlarmRaised:
    case EventCode::kNoInputs:
      return EventLevel::kErr;
    default:
      return EventLevel::kWarn;
  }
}

const char* name_of(EventCode code) {
  static constexpr std::array<const char*, kEventCodeCount> kNames{"started",
                                                                   "scada-stale",
                                                                   "scada-recovered",
                                                                   "input-rejected",
                                                                   "holding-inputs",
                                                                   "steady-state",
                                                                   "no-inputs",
                                                                   "inputs-recovered",
                                                                   "cms-gap",
                                                                   "cms-fault",
                                                                   "cms-recovered",
                                                                   "keyphasor-lost",
                                                                   "keyphasor-recovered",
                                                                   "zone-changed",
                                                                   "alarm-raised",
                                                                   "alarm-cleared",
                                                                   "overrun",
                                                                   "rom-adopted",
                                                                   "calibration-check",
                                                                   "calibration-done",
                                                                   "calibration-skipped",
                                                                   "calibration-failed",
                                                                   "unexplained-mismatch",
                                                                   "diagnosis",
                                                                   "queue-full",
                                                                   "stopped"};
  const auto i = static_cast<std::size_t>(code);
  return i < kNames.size() ? kNames[i] : "?";
}

namespace {

const char* level_name(EventLevel l) {
  switch (l) {
    case EventLevel::kInfo:
      return "INFO";
    case EventLevel::kWarn:
      return "WARN";
    case EventLevel::kErr:
      return "ERR ";
  }
  return "?";
}

// The message of one event (its numbers in words and units).
std::string message(const Event& e) {
  char buf[200];
  switch (e.code) {
    case EventCode::kStarted:
      std::snprintf(buf, sizeof buf, "loop running: period %d µs, ROM step %.3g s", e.a, e.b);
      break;
    case EventCode::kScadaStale:
      std::snprintf(buf, sizeof buf, "SCADA %s: holding the last valid inputs",
                    hal::to_string(static_cast<hal::Status>(e.a)));
      break;
    case EventCode::kScadaRecovered:
      std::snprintf(buf, sizeof buf, "SCADA fresh again");
      break;
    case EventCode::kInputRejected:
      std::snprintf(buf, sizeof buf, "%d SCADA value(s) rejected (non-finite or out of range)",
                    e.a);
      break;
    case EventCode::kHoldingInputs:
      std::snprintf(buf, sizeof buf, "no fresh SCADA: ROM on held inputs (%.0f N·m)", e.b);
      break;
    case EventCode::kSteadyState:
      std::snprintf(buf, sizeof buf,
                    "SCADA stale beyond the hold time: ROM on the controller's steady state "
                    "(%.0f N·m)",
                    e.b);
      break;
    case EventCode::kNoInputs:
      std::snprintf(buf, sizeof buf, "no usable input: ROM stopped, no damage accumulated");
      break;
    case EventCode::kInputsRecovered:
      std::snprintf(buf, sizeof buf, "ROM inputs from SCADA again (%s)",
                    to_string(static_cast<TorqueSource>(e.a)));
      break;
    case EventCode::kCmsGap:
      std::snprintf(buf, sizeof buf, "CMS: %d block(s) lost; calibration window discarded", e.a);
      break;
    case EventCode::kCmsFault:
      std::snprintf(buf, sizeof buf, "CMS link %s", hal::to_string(static_cast<hal::Status>(e.a)));
      break;
    case EventCode::kCmsRecovered:
      std::snprintf(buf, sizeof buf, "CMS link ok again");
      break;
    case EventCode::kKeyphasorLost:
      std::snprintf(buf, sizeof buf, "keyphasor speed invalid: SCADA speed used for orders");
      break;
    case EventCode::kKeyphasorRecovered:
      std::snprintf(buf, sizeof buf, "keyphasor ok");
      break;
    case EventCode::kZoneChanged:
      std::snprintf(buf, sizeof buf, "point%d: ISO 10816-21 zone %s", e.a + 1,
                    to_string(static_cast<VibrationZone>(static_cast<int>(e.b))));
      break;
    case EventCode::kAlarmRaised:
      std::snprintf(buf, sizeof buf, "ALARM raised: a point in zone %s",
                    to_string(static_cast<VibrationZone>(e.a)));
      break;
    case EventCode::kAlarmCleared:
      std::snprintf(buf, sizeof buf, "alarm cleared");
      break;
    case EventCode::kOverrun:
      std::snprintf(buf, sizeof buf, "cycle overrun: %.0f µs late, %d period(s) skipped", e.b, e.a);
      break;
    case EventCode::kRomAdopted:
      std::snprintf(buf, sizeof buf,
                    "calibrated model %d running (its start transient settled over %.2f s, not "
                    "counted)",
                    e.a, e.b);
      break;
    case EventCode::kCalibrationCheck:
      std::snprintf(buf, sizeof buf, "model vs CMS: worst indicator %.2f × its threshold%s", e.b,
                    e.a ? ": calibrating" : "");
      break;
    case EventCode::kCalibrationDone:
      std::snprintf(buf, sizeof buf, "calibration done: worst indicator %.2f × threshold (%s)", e.b,
                    e.a ? "fits" : "does not fit");
      break;
    case EventCode::kCalibrationSkipped:
      std::snprintf(buf, sizeof buf, "calibration window skipped: %s",
                    e.a == 1   ? "CMS gap"
                    : e.a == 2 ? "operating point not steady"
                               : "no operating point");
      break;
    case EventCode::kCalibrationFailed:
      std::snprintf(buf, sizeof buf, "calibration failed (code %d)", e.a);
      break;
    case EventCode::kUnexplainedMismatch:
      std::snprintf(buf, sizeof buf,
                    "calibration cannot reach the thresholds (worst indicator %.2f × its "
                    "threshold, model %d): the missing-physics diagnosis runs",
                    e.b, e.a);
      break;
    case EventCode::kDiagnosis:
      std::snprintf(buf, sizeof buf,
                    "missing-physics diagnosis done: %d effect(s) reported (first at confidence "
                    "%.2f)",
                    e.a, e.b);
      break;
    case EventCode::kQueueFull:
      std::snprintf(buf, sizeof buf, "%s queue full: dropped", e.a == 0 ? "snapshot" : "window");
      break;
    case EventCode::kStopped:
      std::snprintf(buf, sizeof buf, "loop stopped after %d cycles", e.a);
      break;
    default:
      std::snprintf(buf, sizeof buf, "event %d (%d, %g)", static_cast<int>(e.code), e.a, e.b);
  }
  return buf;
}

}  // namespace

std::string EventLog::format(const Event& e) {
  const auto code = static_cast<std::size_t>(e.code);
  if (code >= kEventCodeCount) return {};
  // Per-point codes are limited per point: one point's change must not hide another's.
  const std::size_t point =
      e.code == EventCode::kZoneChanged ? static_cast<std::size_t>(e.a) & 3u : 0u;
  const std::size_t i = code * 4 + point;
  if (seen_[i] && interval_ns_ > 0 && e.stamp_ns - last_ns_[i] < interval_ns_) {
    ++suppressed_[i];
    return {};
  }
  char head[64];
  std::snprintf(head, sizeof head, "[%12.3f] %s %s: ", static_cast<double>(e.stamp_ns) * 1e-9,
                level_name(level_of(e.code)), name_of(e.code));
  std::string line = head + message(e);
  if (suppressed_[i] > 0) {
    line += " (+" + std::to_string(suppressed_[i]) + " more since the last line)";
    suppressed_[i] = 0;
  }
  seen_[i] = true;
  last_ns_[i] = e.stamp_ns;
  return line;
}

}  // namespace app::loop
