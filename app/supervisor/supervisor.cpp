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

bool fresh(hal::Status s) { return s == hal::Status::kOk; }

}  // namespace

Supervisor::Supervisor(const model::Drivetrain& drivetrain, const SupervisorConfig& config)
    : config_(config),
      turbine_(drivetrain.turbine),
      wind_(drivetrain.turbine),
      limits_(drivetrain) {}

SupervisorDecision Supervisor::update(hal::Timestamp now, const hal::ScadaData& scada,
                                      const CycleObservations& seen) {
  SupervisorDecision d;
  d.wind_speed_mps = kNaN;
  d.power_kw = kNaN;
  d.scada_age_s = kNaN;

  // 1–2. Fresh SCADA → ROM inputs.
  bool derived = false;
  if (fresh(seen.scada_status)) {
    // Every delivered value that is finite and plausible; the others rejected and counted.
    wind::ScadaValues values;
    std::uint32_t rejected = 0;
    for (std::size_t i = 0; i < hal::kScadaQuantityCount; ++i) {
      const auto q = static_cast<hal::ScadaQuantity>(i);
      const hal::Measurement& m = scada[q];
      if (!m.valid) continue;  // not delivered: not a rejection
      if (limits_.plausible(q, m.value)) {
        values.set(q, m.value);
      } else {
        ++rejected;
      }
    }
    const wind::RotorTorque t = wind::rotor_torque(turbine_, wind_, values, config_.torque);
    if (t.source != wind::TorqueSource::kNone && std::isfinite(t.torque_nm) &&
        std::isfinite(t.rotor_speed_rpm)) {
      d.rom = {t.rotor_speed_rpm, t.torque_nm};
      d.source = t.source;
      derived = true;
    }
    if (values.has(hal::ScadaQuantity::kWindSpeed)) {
      last_wind_mps_ = values.get(hal::ScadaQuantity::kWindSpeed);
      d.wind_speed_mps = last_wind_mps_;
    }
    if (values.has(hal::ScadaQuantity::kPower)) d.power_kw = values.get(hal::ScadaQuantity::kPower);
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
  if (seen.rom_diverged) d.fault_word |= kFaultRomDiverged;
  d.status_word |= results::kStatusRunning;
  return d;
}

}  // namespace app::supervisor
