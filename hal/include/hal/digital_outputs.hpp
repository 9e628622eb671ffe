#pragma once
// Digital outputs of the box: the watchdog line (toggled by the loop every
// cycle; an external hardware watchdog trips when it stops) and the alarm relay
// (driven by app/supervisor).
//
// SAFETY-CRITICAL. Safe states, applied by deactivate(), by the destructor and
// whenever the backend loses the lines:
//  - watchdog: held low (stops toggling, so the external watchdog trips);
//  - alarm relay: de-energised. The relay is wired fail-safe: energised means
//    "no alarm", so a dead box, a cut wire and deactivate() all raise the alarm.
// Callers pass the logical state (alarm raised or not); backends map it to the
// line level (configurable active-low).
//
// Thread context: set_watchdog / set_alarm from the RT thread: one ioctl on the
// held line (bounded, non-blocking), no allocation.

#include "hal/device.hpp"

namespace hal {

class DigitalOutputs : public Device {
 public:
  /// @param level  watchdog line level to drive (the loop alternates it)
  virtual Status set_watchdog(bool level) = 0;
  /// @param raised  true: alarm raised (relay de-energised)
  virtual Status set_alarm(bool raised) = 0;
};

}  // namespace hal
