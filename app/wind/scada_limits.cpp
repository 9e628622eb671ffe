#include "wind/scada_limits.hpp"

#include <cmath>
#include <cstdio>

#include "model/drivetrain/kinematics.hpp"

namespace app::wind {
namespace {

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

}  // namespace

ScadaLimits::ScadaLimits(const model::Drivetrain& d) {
  using Q = hal::ScadaQuantity;
  const model::Turbine& t = d.turbine;
  double ratio = 1.0;
  if (!d.stages.empty()) {
    const model::Kinematics k(d);
    if (std::isfinite(k.overall_ratio()) && k.overall_ratio() > 0.0) ratio = k.overall_ratio();
  }
  auto set = [this](Q q, double lo, double hi) { ranges_[static_cast<std::size_t>(q)] = {lo, hi}; };
  const double rated_rpm = t.rated_rotor_speed_rpm > 0.0 ? t.rated_rotor_speed_rpm : 30.0;
  set(Q::kWindSpeed, 0.0, kMaxPlausibleWindMps);
  set(Q::kRotorSpeed, kMinPlausibleRotorRpm, kMaxPlausibleSpeedFactor * rated_rpm);
  set(Q::kGeneratorSpeed, kMinPlausibleRotorRpm * ratio,
      kMaxPlausibleSpeedFactor * rated_rpm * ratio);
  const double max_kw = kMaxPlausiblePowerFactor * t.rated_power_w / 1e3;
  set(Q::kPower, -max_kw, max_kw);
  set(Q::kPitch, kMinPlausiblePitchDeg, kMaxPlausiblePitchDeg);
  const double max_nm = kMaxPlausibleTorqueFactor * t.rated_torque_nm;
  set(Q::kRotorTorque, -max_nm, max_nm);
  set(Q::kYawError, -kMaxPlausibleYawErrorDeg, kMaxPlausibleYawErrorDeg);
  set(Q::kAmbientTemperature, kMinPlausibleTemperatureC, kMaxPlausibleTemperatureC);
}

std::string ScadaLimits::why_implausible(hal::ScadaQuantity q, double v) const {
  using Q = hal::ScadaQuantity;
  if (plausible(q, v)) return {};
  const Range& r = range(q);
  const std::string value = num(v) + " " + std::string(hal::scada_quantity_unit(q));
  switch (q) {
    case Q::kWindSpeed:
      return value + " is " +
             (v < 0.0 ? "negative; a wind speed is >= 0"
                      : "beyond any plausible 10-min wind speed (<= " + num(r.max) + " m/s)");
    case Q::kRotorSpeed:
      return value + " is beyond any plausible rotor speed for this turbine (" + num(r.min) +
             " to " + num(r.max) + " rpm = 1.5 x rated)";
    case Q::kGeneratorSpeed:
      return value + " is beyond any plausible generator speed for this turbine (" + num(r.min) +
             " to " + num(r.max) + " rpm = 1.5 x rated x gearbox ratio)";
    case Q::kPower:
      return value + " is beyond twice the rated power (" + num(r.max) + " kW)";
    case Q::kPitch:
      return value + " is outside the plausible blade pitch range " + num(r.min) + " to " +
             num(r.max) + " deg";
    case Q::kRotorTorque:
      return value + " is beyond three times the rated torque (" + num(r.max) + " N·m)";
    case Q::kYawError:
      return value + " is not an angle difference (expected -180 to 180 deg)";
    case Q::kAmbientTemperature:
      return value + " is outside the plausible ambient range " + num(r.min) + " to " + num(r.max) +
             " degC";
    case Q::kCount:
      break;
  }
  return value + " is implausible";
}

}  // namespace app::wind
