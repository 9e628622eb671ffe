#pragma once
// The rotor (gearbox input) torque from SCADA values: the one place that decides where the
// torque comes from, used by history mode (`drivetwin damage`), the online accumulator
// check, `drivetwin torque`'s reference and the real-time loop.
//
// Sources, in order of preference (kAuto), each only when its inputs are present:
//   1. measured rotor torque torque_nm: T = |T_meas|;
//   2. electrical power and rotor speed (ω ≥ kMinPowerSpeedRpm): the electrical power is
//      P_el = η·P_aero − P_0 (model/wind/corrections.hpp: drivetrain_efficiency η, no-load
//      loss P_0), so T = P_aero/ω = (P_el + P_0)/(η·ω) while generating (P_el > 0), 0 when
//      not (idling: no P_0 drawn through the drivetrain);
//   3. wind speed through the Cp(λ, β) wind load model (model/wind): at the measured rotor
//      speed (and pitch when asked) if present, else the controller's steady state, which
//      then also gives the rotor speed.
// The rotor speed is the measured one (−1..0 read as 0) unless the wind model's steady state
// supplies it. Values must have passed ScadaLimits (wind/scada_limits.hpp) before.
//
// Thread context: rotor_torque() is allocation-free and lock-free (RT-safe).

#include <array>
#include <cstdint>

#include "hal/scada_quantity.hpp"
#include "model/drivetrain/description.hpp"
#include "model/wind/wind_load.hpp"
#include "wind/torque_source_kind.hpp"

namespace app::wind {

/// Below this rotor speed power says nothing about torque (P/ω undefined) [rpm].
inline constexpr double kMinPowerSpeedRpm = 0.1;

// Where a torque came from: TorqueSource (wind/torque_source_kind.hpp); rotor_torque() gives
// kNone, kMeasuredTorque, kPower or kWind.

/// Which source to use. kAuto: the order above. The others force one source (values without
/// it give kNone); kWindSteady also takes the rotor speed from the wind model's steady state,
/// ignoring the measured one (to drive one turbine's drivetrain with another site's wind).
enum class TorquePreference : std::uint8_t { kAuto, kTorque, kPower, kWind, kWindSteady };

/// One set of SCADA values (a CSV row, or the loop's latest data), by hal::ScadaQuantity.
struct ScadaValues {
  std::array<double, hal::kScadaQuantityCount> value{};  // in each quantity's unit
  std::array<bool, hal::kScadaQuantityCount> present{};  // false: absent, stale or invalid
  double get(hal::ScadaQuantity q) const { return value[static_cast<std::size_t>(q)]; }
  bool has(hal::ScadaQuantity q) const { return present[static_cast<std::size_t>(q)]; }
  void set(hal::ScadaQuantity q, double v) {
    value[static_cast<std::size_t>(q)] = v;
    present[static_cast<std::size_t>(q)] = true;
  }
};

struct RotorTorque {
  double torque_nm = 0.0;        // [N·m] ≥ 0
  double rotor_speed_rpm = 0.0;  // [rpm] ≥ 0: measured, or the wind model's steady state
  TorqueSource source = TorqueSource::kNone;
  model::wind::WindLoadOutput wind;  // the wind model's output when source == kWind
};

/// Options of the wind source.
struct WindSourceOptions {
  bool measured_pitch = true;  // feed a measured pitch into Cp(λ, β)
  model::wind::Inflow inflow{};
};

/// T_rotor = max(0, P_el + P_0)/(η·ω) [N·m]; 0 when ω < kMinPowerSpeedRpm or η ≤ 0.
double rotor_torque_from_power_nm(const model::Turbine& turbine, double power_kw,
                                  double rotor_speed_rpm);

/// The rotor torque and speed of `values` (see the file comment).
RotorTorque rotor_torque(const model::Turbine& turbine, const model::wind::WindLoad& wind,
                         const ScadaValues& values,
                         TorquePreference preference = TorquePreference::kAuto,
                         const WindSourceOptions& options = {});

}  // namespace app::wind
