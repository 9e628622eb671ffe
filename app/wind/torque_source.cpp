#include "wind/torque_source.hpp"

#include "units.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "model/wind/corrections.hpp"

namespace app::wind {
namespace {
using Q = hal::ScadaQuantity;
}  // namespace

double rotor_torque_from_power_nm(const model::Turbine& t, double power_kw,
                                  double rotor_speed_rpm) {
  if (!(rotor_speed_rpm >= kMinPowerSpeedRpm) || !(t.drivetrain_efficiency > 0.0)) return 0.0;
  // Not generating (P_el ≤ 0: idling, parked or the generator off the grid): the no-load
  // loss P_0 is not being drawn through the drivetrain, and (P_el + P_0)/(η·ω) would turn it
  // into a torque that grows without bound as an idling rotor slows (2–3 × rated at
  // 0.2 rpm in the Kelmarsh data). The load is the idling drag: taken as 0.
  if (!(power_kw > 0.0)) return 0.0;
  // P_aero = (P_el + P_0)/η (model/wind/corrections.hpp), the inverse of what the wind
  // model's electrical_power_w() predicts.
  const double p_aero_w = model::wind::aerodynamic_power_w(power_kw * 1e3, t.drivetrain_efficiency,
                                                           t.corrections.no_load_loss_w);
  return std::max(0.0, p_aero_w) / (rotor_speed_rpm * kRpmToRadS);
}

RotorTorque rotor_torque(const model::Turbine& turbine, const model::wind::WindLoad& wind,
                         const ScadaValues& v, TorquePreference pref,
                         const WindSourceOptions& options) {
  RotorTorque r;
  const bool any = pref == TorquePreference::kAuto;
  const bool steady = pref == TorquePreference::kWindSteady;
  const bool has_speed = v.has(Q::kRotorSpeed) && !steady;
  const double rpm = has_speed ? std::max(0.0, v.get(Q::kRotorSpeed)) : 0.0;
  r.rotor_speed_rpm = rpm;
  if ((any || pref == TorquePreference::kTorque) && v.has(Q::kRotorTorque)) {
    r.torque_nm = std::abs(v.get(Q::kRotorTorque));
    r.source = TorqueSource::kMeasuredTorque;
    return r;
  }
  if ((any || pref == TorquePreference::kPower) && v.has(Q::kPower) && has_speed &&
      rpm >= kMinPowerSpeedRpm) {
    r.torque_nm = rotor_torque_from_power_nm(turbine, v.get(Q::kPower), rpm);
    r.source = TorqueSource::kPower;
    return r;
  }
  const bool use_wind = any || pref == TorquePreference::kWind || steady;
  if (use_wind && v.has(Q::kWindSpeed)) {
    const double ws = v.get(Q::kWindSpeed);
    if (has_speed) {
      const bool pitch = options.measured_pitch && v.has(Q::kPitch);
      r.wind = wind.with_rotor_speed(
          ws, rpm * kRpmToRadS, pitch ? v.get(Q::kPitch) * kDegToRad : 0.0, pitch, options.inflow);
    } else {
      r.wind = wind.steady_state(ws);
      r.rotor_speed_rpm = r.wind.rotor_speed_rad_s / kRpmToRadS;
    }
    r.torque_nm = std::abs(r.wind.torque_nm);
    r.source = TorqueSource::kWind;
  }
  return r;
}

}  // namespace app::wind
