#pragma once
// The supervisor: every safety- and validity-relevant decision of the twin, in one place,
// run every cycle (style.md §1, after the Crazyflie's supervisorUpdate). The loop never
// stops for bad input: the supervisor picks a degraded mode, says so in the status and
// fault words, and counts what it rejected.
//
// Decisions, in order:
//  1. SCADA values: a value is used only when the source delivered it (valid), it is finite
//     and inside its plausibility range (the one set of limits, app/wind/scada_limits.hpp);
//     otherwise it is rejected and counted, and the cycle continues without it.
//  2. ROM inputs (rotor speed, input torque) from the one torque source
//     (app/wind/torque_source.hpp, the same `drivetwin damage` uses): measured torque, else
//     electrical power and rotor speed (T = (P_el + P_0)/(η ω)), else wind speed through the
//     wind load model at the measured rotor speed (or the controller's steady state without
//     one). `inputs.torque_source` may force one.
//  3. Degraded modes when step 2 finds nothing (SCADA silent, stale, disconnected, every
//     value rejected): the last valid inputs are held for `inputs.scada_hold_s`
//     (TorqueSource::kHeld), then the controller's steady-state operating point at the last
//     valid wind speed (kSteadyState), both flagged degraded; with no valid wind ever, no
//     input (kNone): the ROM is not stepped and nothing is accumulated, flagged.
//  4. CMS: a sequence gap or bus-off in this cycle marks the CMS faulty (status bit) and the
//     calibration window in progress void (the loop skips it; fault bit kFaultCmsGap).
//  5. Keyphasor: invalid speed (stuck, missing) sets its status bit; the twin falls back to
//     the SCADA rotor speed × ratio for order tracking.
//  6. Alarm output (SAFETY-CRITICAL): raised while any measurement point is in the
//     configured alarm zone or worse (ISO 10816-21, vibration_zones.hpp). The relay is
//     wired fail-safe (hal/digital_outputs.hpp): a dead loop raises it too.
//
// Thread context: construct at start-up; update() on the RT thread: no allocation, no
// locks, no clock (now is passed in), bounded work.

#include <array>
#include <cstdint>

#include "hal/scada_source.hpp"
#include "hal/status.hpp"
#include "loop/snapshot.hpp"
#include "model/drivetrain/description.hpp"
#include "model/dynamics/rom.hpp"
#include "model/wind/wind_load.hpp"
#include "wind/scada_limits.hpp"
#include "wind/torque_source.hpp"

namespace app::supervisor {

/// Fault bits (Snapshot::fault_word, register 2). Permanent: never renumber, only append.
enum FaultBit : std::uint16_t {
  kFaultScadaStale = 1u << 0,         // SCADA stale, silent or disconnected this cycle
  kFaultInputRejected = 1u << 1,      // a SCADA value was rejected this cycle
  kFaultHoldingInputs = 1u << 2,      // the ROM runs on held inputs
  kFaultSteadyState = 1u << 3,        // the ROM runs on the controller's steady state
  kFaultNoInputs = 1u << 4,           // no usable input: the ROM is not stepped
  kFaultCmsGap = 1u << 5,             // CMS blocks lost this cycle: calibration skipped
  kFaultCmsBusOff = 1u << 6,          // CMS bus-off / error / silent
  kFaultKeyphasor = 1u << 7,          // keyphasor speed invalid
  kFaultZoneAlert = 1u << 8,          // a point in ISO 10816-21 zone C
  kFaultZoneAlarm = 1u << 9,          // a point in zone D (or the configured alarm zone)
  kFaultCalibrationUnfit = 1u << 10,  // the last calibration could not reach the thresholds
  kFaultOverrun = 1u << 11,           // a cycle overran since the last snapshot
  kFaultQueueFull = 1u << 12,         // a snapshot or log event was dropped (consumer behind)
  kFaultPersistence = 1u << 13,       // the last checkpoint failed (persistence thread)
  kFaultRomDiverged = 1u << 14,       // the ROM's output was not finite or beyond any gearbox's
                                      // (steps not counted, the ROM restarted from equilibrium)
};

struct SupervisorConfig {
  wind::TorquePreference torque = wind::TorquePreference::kAuto;  // inputs.torque_source
  double hold_s = 60.0;                                           // [s]
  loop::VibrationZone alarm_zone = loop::VibrationZone::kD;
};

/// What the supervisor saw this cycle besides SCADA.
struct CycleObservations {
  hal::Status scada_status = hal::Status::kNoData;
  bool cms_gap = false;    // blocks lost since the last cycle
  bool cms_fault = false;  // bus-off, errors, silent
  bool keyphasor_valid = false;
  bool overrun = false;            // the previous cycle overran
  bool calibrated = false;         // a calibrated model is running
  bool calibration_unfit = false;  // the last calibration did not fit
  bool persistence_failed = false;
  bool queue_full = false;
  bool rom_diverged = false;  // since the last snapshot
  std::array<loop::VibrationZone, loop::kSnapshotPoints> zones{};
};

struct SupervisorDecision {
  bool rom_valid = false;            // step the ROM with `rom` this cycle
  model::dynamics::RomInputs rom{};  // [rpm], [N·m]
  loop::TorqueSource source = loop::TorqueSource::kNone;
  double wind_speed_mps = 0.0;            // [m/s] the wind the inputs stand on (NaN: none)
  double power_kw = 0.0;                  // [kW] (NaN: none)
  double scada_age_s = 0.0;               // [s] age of the SCADA values used (NaN: none)
  bool alarm = false;                     // SAFETY-CRITICAL: drive the alarm output raised
  std::uint16_t status_word = 0;          // app::results::StatusBit
  std::uint16_t fault_word = 0;           // FaultBit
  std::uint32_t rejected_this_cycle = 0;  // SCADA values rejected
};

class Supervisor {
 public:
  Supervisor(const model::Drivetrain& drivetrain, const SupervisorConfig& config);

  /// One cycle's decisions. @param now loop time [ns]; @param scada the source's latest data.
  SupervisorDecision update(hal::Timestamp now, const hal::ScadaData& scada,
                            const CycleObservations& seen);

  std::uint64_t rejected_total() const { return rejected_total_; }
  const SupervisorConfig& config() const { return config_; }

 private:
  SupervisorConfig config_;
  model::Turbine turbine_;
  model::wind::WindLoad wind_;
  wind::ScadaLimits limits_;
  // Last valid inputs.
  bool have_last_ = false;
  hal::Timestamp last_valid_{0};
  model::dynamics::RomInputs last_rom_{};
  double last_wind_mps_ = -1.0;  // < 0: never had a valid wind
  std::uint64_t rejected_total_ = 0;
};

}  // namespace app::supervisor
