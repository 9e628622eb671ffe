#pragma once
// SCADA source: the latest operating data of the turbine controller (polled
// over Modbus by an I/O thread, replayed from a recording, or simulated).
// Each quantity carries its own time stamp and validity, so the supervisor can
// tell a silent controller (everything stale) from one missing register.
//
// Thread context: read() from the RT thread: copies the latest snapshot,
// wait-free, never blocks on the bus, never allocates.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "hal/clock.hpp"
#include "hal/device.hpp"
#include "hal/scada_quantity.hpp"

namespace hal {

/// One value with the time it was measured (received) and whether it is usable.
struct Measurement {
  double value = 0.0;  // in the quantity's unit (kScadaQuantities)
  Timestamp stamp{0};  // [ns] when it was received (source clock)
  bool valid = false;  // false: never received, decode error, or flagged invalid
};

/// The latest operating data.
struct ScadaData {
  std::array<Measurement, kScadaQuantityCount> values{};
  Timestamp last_update{0};        // [ns] last successful poll / replay step
  std::uint32_t update_count = 0;  // successful polls so far
  std::uint32_t error_count = 0;   // failed polls / decode errors so far
  std::uint32_t reconnect_count = 0;

  const Measurement& operator[](ScadaQuantity q) const {
    return values[static_cast<std::size_t>(q)];
  }
  Measurement& operator[](ScadaQuantity q) { return values[static_cast<std::size_t>(q)]; }
};

class ScadaSource : public Device {
 public:
  /// Copies the latest operating data into `out` and judges its age at `now`.
  /// @param now  current time [ns], from the loop's Clock
  /// @return kOk: fresh data; kStale: the newest data is older than the source's
  ///         stale limit (values keep their last content, `valid` as received);
  ///         kNoData: nothing received yet; kDisconnected: peer gone (data as kStale);
  ///         kWrongState: not active.
  virtual Status read(Timestamp now, ScadaData& out) = 0;
};

}  // namespace hal
