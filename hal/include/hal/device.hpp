#pragma once
// Lifecycle every hal device follows (after ros2_control's hardware components):
//
//   construct  (no I/O, no allocation beyond members)
//     → configure()   open the bus, allocate every buffer, start I/O threads
//     → activate()    outputs live; inputs start flowing to the RT side
//     → read/write    RT thread: bounded time, never blocks, never allocates
//     → deactivate()  outputs to their safe states; inputs stop
//     → (activate() again, or destruction, which deactivates and closes)
//
// Thread context: configure/activate/deactivate from the non-RT control thread,
// never concurrently with each other; read/write from the single RT thread.

#include <cstdint>

#include "hal/status.hpp"

namespace hal {

enum class LifecycleState : std::uint8_t { kUnconfigured, kInactive, kActive };

class Device {
 public:
  virtual ~Device() = default;
  /// Opens the bus and allocates. May block (bounded by the device's own timeouts).
  virtual Status configure() = 0;
  /// Makes outputs live / starts delivering inputs.
  virtual Status activate() = 0;
  /// Puts outputs into their safe state and stops inputs. Must succeed in any
  /// state; returns the first error but always tries every output.
  virtual Status deactivate() = 0;
  virtual LifecycleState state() const = 0;
};

}  // namespace hal
