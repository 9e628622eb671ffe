#pragma once
// Plausibility limits of SCADA values for one turbine: the one set used by every reader of
// SCADA data — the offline commands (torque, damage, fit-cp) and the real-time loop's
// supervisor (a value outside its limit is rejected and counted, never used).
//
// Limits (each justified by what no working turbine reports):
//   wind speed        0 .. 75 m/s            above any recorded 10-min mean
//   rotor speed      −1 .. 1.5 × rated rpm   −1..0 is sensor offset (read as 0)
//   generator speed  −1·ratio .. 1.5 × rated × ratio rpm (the gearbox ratio)
//   power            |P| ≤ 2 × rated kW
//   pitch           −15 .. 120 deg
//   rotor torque     |T| ≤ 3 × rated N·m      (a reading beyond is a sensor fault)
//   yaw error        |γ| ≤ 180 deg           an angle difference
//   ambient temp.   −60 .. 60 °C             beyond any nacelle ambient record
//
// Thread context: built at start-up; check() is allocation-free (RT-safe).

#include <array>
#include <string>

#include "hal/scada_quantity.hpp"
#include "model/drivetrain/description.hpp"

namespace app::wind {

inline constexpr double kMaxPlausibleWindMps = 75.0;        // [m/s]
inline constexpr double kMaxPlausibleSpeedFactor = 1.5;     // [-] × rated rotor speed
inline constexpr double kMinPlausibleRotorRpm = -1.0;       // [rpm] small negatives: sensor offset
inline constexpr double kMaxPlausiblePowerFactor = 2.0;     // [-] × rated power
inline constexpr double kMaxPlausibleTorqueFactor = 3.0;    // [-] × rated torque
inline constexpr double kMinPlausiblePitchDeg = -15.0;      // [deg]
inline constexpr double kMaxPlausiblePitchDeg = 120.0;      // [deg]
inline constexpr double kMinPlausibleTemperatureC = -60.0;  // [°C]
inline constexpr double kMaxPlausibleTemperatureC = 60.0;   // [°C]
inline constexpr double kMaxPlausibleYawErrorDeg = 180.0;   // [deg]

struct Range {
  double min = 0.0;
  double max = 0.0;
};

class ScadaLimits {
 public:
  /// The limits for `drivetrain`'s turbine (rated speed, power and torque; the gearbox
  /// ratio for the generator speed).
  explicit ScadaLimits(const model::Drivetrain& drivetrain);

  const Range& range(hal::ScadaQuantity q) const { return ranges_[static_cast<std::size_t>(q)]; }
  bool plausible(hal::ScadaQuantity q, double value) const {
    const Range& r = range(q);
    return value >= r.min && value <= r.max;  // false for NaN
  }
  /// "" when plausible, else e.g. "1480 rpm is beyond any plausible rotor speed for this
  /// turbine (-1 to 22.2 rpm = 1.5 x rated)". Allocates: for messages, not the RT path.
  std::string why_implausible(hal::ScadaQuantity q, double value) const;

 private:
  std::array<Range, hal::kScadaQuantityCount> ranges_{};
};

}  // namespace app::wind
