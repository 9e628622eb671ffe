#pragma once
// Status codes every hal call returns. I/O faults are data, not control flow:
// a read that finds nothing new returns kNoData, a source whose data is too old
// kStale, and the loop carries on (the supervisor picks the degraded mode).
// Thread context: any; to_string() is constexpr and allocation-free.

#include <cstdint>

namespace hal {

enum class [[nodiscard]] Status : std::uint8_t{
    kOk = 0,
    kNoData,         // nothing new since the last read (not an error)
    kStale,          // a value exists but is older than the configured limit
    kTimeout,        // a bus transaction did not complete in time
    kDisconnected,   // the peer is gone; the I/O thread is reconnecting
    kBusOff,         // CAN controller bus-off; recovery in progress
    kBusError,       // CAN error frames received (error passive/warning, protocol error)
    kProtocolError,  // a frame or response that does not follow the protocol (garbage)
    kGap,            // sequence gap: data was lost
    kOverflow,       // a bounded queue was full; data dropped and counted
    kInvalidConfig,  // configure() rejected the configuration
    kIoError,        // an OS call failed (open, bind, ioctl ...)
    kWrongState,     // call not allowed in the current lifecycle state
    kEndOfData,      // a replay reached the end of its recording
    kDenied,         // a request was refused (not writable, not allowed)
};

constexpr const char* to_string(Status s) {
  switch (s) {
    case Status::kOk:
      return "ok";
    case Status::kNoData:
      return "no data";
    case Status::kStale:
      return "stale";
    case Status::kTimeout:
      return "timeout";
    case Status::kDisconnected:
      return "disconnected";
    case Status::kBusOff:
      return "bus-off";
    case Status::kBusError:
      return "bus error";
    case Status::kProtocolError:
      return "protocol error";
    case Status::kGap:
      return "gap";
    case Status::kOverflow:
      return "overflow";
    case Status::kInvalidConfig:
      return "invalid config";
    case Status::kIoError:
      return "I/O error";
    case Status::kWrongState:
      return "wrong lifecycle state";
    case Status::kEndOfData:
      return "end of data";
    case Status::kDenied:
      return "denied";
  }
  return "unknown";
}

}  // namespace hal
