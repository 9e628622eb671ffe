#pragma once
// Where the ROM's input torque came from: the one enum for the torque source
// (wind/torque_source.hpp chooses among the measured sources; the supervisor adds the two
// degraded fallbacks) that `drivetwin damage`, the real-time loop's snapshot, its events and
// the trends database all use. The values are persisted (snapshot, trends): append only.
//
// Thread context: constexpr; any thread.

#include <cstdint>

namespace app::wind {

enum class TorqueSource : std::uint8_t {
  kNone = 0,            // no usable input: the ROM is not stepped, nothing accumulated
  kMeasuredTorque = 1,  // the controller's rotor torque
  kPower = 2,           // electrical power and rotor speed (drivetrain losses added back)
  kWind = 3,            // wind speed through the wind load model
  kHeld = 4,            // supervisor: SCADA stale, the last valid inputs held for a bounded time
  kSteadyState = 5,     // supervisor: SCADA stale too long, the controller's steady-state torque
                        // at the last valid wind / speed (flagged degraded)
};

constexpr const char* to_string(TorqueSource source) {
  switch (source) {
    case TorqueSource::kNone:
      return "none";
    case TorqueSource::kMeasuredTorque:
      return "measured torque";
    case TorqueSource::kPower:
      return "power";
    case TorqueSource::kWind:
      return "wind";
    case TorqueSource::kHeld:
      return "held";
    case TorqueSource::kSteadyState:
      return "steady-state";
  }
  return "?";
}

}  // namespace app::wind
