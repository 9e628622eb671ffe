// The supervisor's decisions: see supervisor.hpp.
#include "supervisor/supervisor.hpp"

#include <cmath>
#include <limits>
#include <numbers>

#include "results/register_map.hpp"

namespace app::supervisor {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kRpmToRadS = 2.0 * std::numbers::pi / 60.0;
// Negative rotor speeds down to −1 rpm are sensor offset and read as 0 (as damage history).
constexpr double kSpeedOffsetRpm = 1.0;

bool fresh(hal::Status s) { return s == hal::Status::kOk; }

}  // namespace

Supervisor::Supervisor(const model::Drivetrain& drivetrain, const SupervisorConfig& config)
    : config_(config), wind_(drivetrain.turbine) {
  const model::Turbine& t = drivetrain.turbine;
  eta_ = t.drivetrain_efficiency > 0.0 ? t.drivetrain_efficiency : 1.0;
  rated_speed_rpm_ = t.rated_rotor_speed_rpm;
  rated_torque_nm_ = t.rated_torque_nm;
  rated_power_kw_ = t.rated_power_w / 1e3;
}

double Supervisor::usable(const hal::ScadaData& scada, hal::ScadaQuantity q, double lo, double hi,
                          std::uint32_t& rejected) const {
  const hal::Measurement& m = scada[q];
  if (!m.valid) return kNaN;  // not delivered: not a rejection
  if (!std::isfinite(m.value) || m.value < lo || m.value > hi) {
    ++rejected;
    return kNaN;
  }
  return m.value;
}

SupervisorDecision Supervisor::update(hal::Timestamp now, const hal::ScadaData& scada,
                                      const CycleObservations& seen) {
  SupervisorDecision d;
  d.wind_speed_mps = kNaN;
  d.power_kw = kNaN;
  d.scada_age_s = kNaN;
  const double inf = std::numeric_limits<double>::infinity();

  // 1–2. Fresh SCADA → ROM inputs.
  bool derived = false;
  if (fresh(seen.scada_status)) {
    std::uint32_t rejected = 0;
    const double max_rpm = rated_speed_rpm_ > 0 ? config_.max_speed_factor * rated_speed_rpm_ : inf;
    const double max_nm = rated_torque_nm_ > 0 ? config_.max_torque_factor * rated_torque_nm_ : inf;
    const double max_kw = rated_power_kw_ > 0 ? config_.max_power_factor * rated_power_kw_ : inf;
    const double wind =
        usable(scada, hal::ScadaQuantity::kWindSpeed, 0.0, config_.max_wind_mps, rejected);
    double rpm =
        usable(scada, hal::ScadaQuantity::kRotorSpeed, -kSpeedOffsetRpm, max_rpm, rejected);
    const double torque =
        usable(scada, hal::ScadaQuantity::kRotorTorque, -max_nm, max_nm, rejected);
    // A generator motoring from the grid reads slightly negative power: not an error.
    const double power = usable(scada, hal::ScadaQuantity::kPower, -0.2 * max_kw, max_kw, rejected);
    const double pitch = usable(scada, hal::ScadaQuantity::kPitch, -10.0, 95.0, rejected);
    if (!std::isnan(rpm)) rpm = std::max(rpm, 0.0);
    const TorquePreference pref = config_.torque;
    const bool any = pref == TorquePreference::kAuto;
    if ((any || pref == TorquePreference::kTorque) && !std::isnan(torque) && !std::isnan(rpm)) {
      d.rom = {rpm, std::abs(torque)};
      d.source = loop::TorqueSource::kMeasured;
      derived = true;
    } else if ((any || pref == TorquePreference::kPower) && !std::isnan(power) &&
               !std::isnan(rpm) && rpm > min_power_speed_rpm_) {
      d.rom = {rpm, std::max(0.0, power) * 1e3 / (eta_ * rpm * kRpmToRadS)};
      d.source = loop::TorqueSource::kPower;
      derived = true;
    } else if ((any || pref == TorquePreference::kWind) && !std::isnan(wind)) {
      model::wind::WindLoadOutput out;
      if (!std::isnan(rpm)) {
        const bool has_pitch = !std::isnan(pitch);
        out = wind_.with_rotor_speed(wind, rpm * kRpmToRadS,
                                     has_pitch ? pitch * std::numbers::pi / 180.0 : 0.0, has_pitch);
        d.rom = {rpm, std::abs(out.torque_nm)};
      } else {
        out = wind_.steady_state(wind);
        d.rom = {out.rotor_speed_rad_s / kRpmToRadS, std::abs(out.torque_nm)};
      }
      d.source = loop::TorqueSource::kWind;
      derived = std::isfinite(d.rom.input_torque_nm) && std::isfinite(d.rom.rotor_speed_rpm);
    }
    if (!std::isnan(wind)) last_wind_mps_ = wind;
    d.wind_speed_mps = wind;
    d.power_kw = power;
    d.scada_age_s = std::chrono::duration<double>(now - scada.last_update).count();
    d.rejected_this_cycle = rejected;
    rejected_total_ += rejected;
    if (rejected > 0) d.fault_word |= kFaultInputRejected;
  } else {
    d.fault_word |= kFaultScadaStale;
    d.status_word |= results::kStatusScadaStale;
  }

  // 3. Degraded modes.
  if (derived) {
    have_last_ = true;
    last_valid_ = now;
    last_rom_ = d.rom;
    last_source_ = d.source;
    d.rom_valid = true;
  } else {
    const double since_s = std::chrono::duration<double>(now - last_valid_).count();
    if (have_last_ && since_s <= config_.hold_s) {
      d.rom = last_rom_;
      d.source = loop::TorqueSource::kHeld;
      d.rom_valid = true;
      d.fault_word |= kFaultHoldingInputs;
    } else if (last_wind_mps_ >= 0.0) {
      const model::wind::WindLoadOutput out = wind_.steady_state(last_wind_mps_);
      d.rom = {out.rotor_speed_rad_s / kRpmToRadS, std::abs(out.torque_nm)};
      d.source = loop::TorqueSource::kSteadyState;
      d.rom_valid = std::isfinite(d.rom.input_torque_nm) && std::isfinite(d.rom.rotor_speed_rpm);
      d.wind_speed_mps = last_wind_mps_;
      d.fault_word |= kFaultSteadyState;
    } else {
      d.fault_word |= kFaultNoInputs;
    }
    d.status_word |= results::kStatusDegraded;
  }

  // 4–5. CMS and keyphasor.
  if (seen.cms_gap) d.fault_word |= kFaultCmsGap;
  if (seen.cms_fault) d.fault_word |= kFaultCmsBusOff;
  if (seen.cms_gap || seen.cms_fault) d.status_word |= results::kStatusCmsFault;
  if (!seen.keyphasor_valid) {
    d.fault_word |= kFaultKeyphasor;
    d.status_word |= results::kStatusKeyphasorFault;
  }

  // 6. Alarm output. SAFETY-CRITICAL: raised while any point is at or beyond the alarm zone.
  for (const loop::VibrationZone z : seen.zones) {
    if (z == loop::VibrationZone::kC) d.fault_word |= kFaultZoneAlert;
    if (z == loop::VibrationZone::kD) d.fault_word |= kFaultZoneAlarm;
    if (static_cast<int>(z) >= static_cast<int>(config_.alarm_zone)) d.alarm = true;
  }
  if (d.alarm) d.status_word |= results::kStatusAlarm;

  if (seen.overrun) {
    d.fault_word |= kFaultOverrun;
    d.status_word |= results::kStatusOverrun;
  }
  if (seen.calibrated) d.status_word |= results::kStatusCalibrated;
  if (seen.calibration_unfit) d.fault_word |= kFaultCalibrationUnfit;
  if (seen.persistence_failed) d.fault_word |= kFaultPersistence;
  if (seen.queue_full) d.fault_word |= kFaultQueueFull;
  d.status_word |= results::kStatusRunning;
  return d;
}

}  // namespace app::supervisor
