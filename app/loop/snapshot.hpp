#pragma once
// The results snapshot: everything the real-time loop knows at the end of a cycle, as one
// plain fixed-size struct that the loop publishes without waiting (app/loop/mailbox.hpp)
// and every non-RT consumer reads — the results register image (app/results), the trends
// database, the persistence thread, the text log, a dashboard.
//
// Every quantity carries its unit in its name or comment; times are the loop's clock
// (CLOCK_MONOTONIC on the box, recording time in a replay), never wall time. A value the
// loop does not have is NaN (floats) — never a made-up 0 — and the status word says why.
//
// Layout rules (consumers may persist it): plain, trivially copyable, fixed size; a later
// version appends fields and bumps kSnapshotVersion, never reorders.
//
// Thread context: filled by the RT thread (no allocation); copied by any thread.

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>

#include "model/fatigue/drivetrain_channels.hpp"
#include "results/register_map.hpp"
#include "wind/torque_source_kind.hpp"

namespace app::loop {

inline constexpr std::uint32_t kSnapshotVersion = 1;
/// Measurement points (CMS accelerometer positions compared with the model): point1, point2.
inline constexpr std::size_t kSnapshotPoints = 2;
inline constexpr float kNoValue = std::numeric_limits<float>::quiet_NaN();

/// Where the ROM's input torque came from this cycle (the supervisor's choice): the one
/// enum of wind/torque_source_kind.hpp.
using TorqueSource = wind::TorqueSource;
using wind::to_string;

/// ISO 10816-21 evaluation zone of a measurement (Annex A boundaries; see docs/run.md).
enum class VibrationZone : std::uint8_t {
  kUnknown = 0,  // no complete evaluation interval yet, or the CMS channel is faulty
  kAB = 1,       // below the B/C boundary: acceptable for long-term operation
  kC = 2,        // between B/C and C/D: ALERT (limited operation; plan action)
  kD = 3,        // above C/D: ALARM (damaging)
};
const char* to_string(VibrationZone zone);

/// One CMS measurement point: the broadband values ISO 10816-21 evaluates (interval rms over
/// the standard's evaluation periods) and the point's zone (the worst of its bands).
struct PointSnapshot {
  float accel_rms_10_2000_mps2 = kNoValue;     // [m/s²] acceleration, 10 Hz–2 kHz, last interval
  float velocity_rms_10_1000_mmps = kNoValue;  // [mm/s] velocity, 10 Hz–1 kHz, last interval
  float accel_rms_01_10_mps2 = kNoValue;       // [m/s²] acceleration, 0.1–10 Hz, last interval
  float rms_mps2 = kNoValue;                   // [m/s²] raw broadband rms of the last window
  float kurtosis = kNoValue;                   // [-] of the last window
  VibrationZone zone = VibrationZone::kUnknown;
  std::uint8_t reserved[3] = {};
};

/// Loop timing and counters since start.
struct LoopCounters {
  std::uint64_t cycles = 0;             // [-] cycles run
  std::uint64_t overruns = 0;           // [-] cycles that ended after their deadline
  std::uint64_t skipped_periods = 0;    // [-] periods skipped after overruns
  std::uint64_t rom_steps = 0;          // [-] ROM steps taken
  std::uint64_t cms_blocks = 0;         // [-] CMS blocks drained
  std::uint64_t cms_gaps = 0;           // [-] CMS sequence gaps seen (from the stream's counters)
  std::uint64_t keyphasor_edges = 0;    // [-] keyphasor edges drained
  std::uint64_t rejected_inputs = 0;    // [-] non-finite / out-of-range inputs rejected
  std::uint64_t snapshots_dropped = 0;  // [-] snapshots not queued (consumer behind)
  std::uint64_t events_dropped = 0;     // [-] log events not queued
  std::uint64_t rom_adoptions = 0;      // [-] calibrated ROMs adopted
  float cycle_time_us = kNoValue;       // [µs] compute time of the last cycle
  float cycle_time_max_us = kNoValue;   // [µs] largest compute time since start
  float wakeup_latency_us = kNoValue;   // [µs] lateness of the last wake-up
  float wakeup_latency_max_us = kNoValue;  // [µs] largest wake-up lateness since start
};

struct Snapshot {
  std::uint32_t version = kSnapshotVersion;
  std::uint32_t sequence = 0;  // [-] publish counter (gaps: snapshots dropped)
  std::int64_t stamp_ns = 0;   // [ns] loop time at the end of the cycle

  // Operating point the ROM was driven with this cycle, and where it came from.
  float rotor_speed_rpm = kNoValue;  // [rpm] rotor (low-speed shaft)
  float rotor_torque_nm = kNoValue;  // [N·m] gearbox input torque
  float wind_speed_mps = kNoValue;   // [m/s] nacelle anemometer (SCADA)
  float power_kw = kNoValue;         // [kW] electrical power (SCADA)
  float hss_speed_rpm = kNoValue;    // [rpm] from the keyphasor
  float scada_age_s = kNoValue;      // [s] age of the newest SCADA values used
  TorqueSource torque_source = TorqueSource::kNone;
  std::uint8_t reserved0[3] = {};

  // Supervisor.
  std::uint16_t status_word = 0;             // app::results::StatusBit
  std::uint16_t fault_word = 0;              // app::supervisor fault bits (docs/run.md)
  std::uint16_t calibration_generation = 0;  // [-] calibrated ROMs adopted so far (+ persisted)
  std::uint16_t reserved1 = 0;

  // Model vs measurement (the paper's similarity indicators of the last comparison).
  float calibration_residual = kNoValue;  // [-] worst indicator / its threshold (≤ 1: fits)
  std::array<std::array<float, 3>, kSnapshotPoints> fit{
      {{kNoValue, kNoValue, kNoValue}, {kNoValue, kNoValue, kNoValue}}};  // [-] f1, f2, f3
  std::array<PointSnapshot, kSnapshotPoints> points{};

  // Damage per channel (model::fatigue::ChannelSet order: every gear × failure mode, every
  // bearing, per planet), with the time and revolutions accumulated.
  double elapsed_s = 0.0;           // [s] time accumulated into the damage (valid steps)
  double rotor_revolutions = 0.0;   // [rev] rotor revolutions accumulated
  std::uint32_t channel_count = 0;  // [-] channels in use
  std::uint32_t reserved2 = 0;
  std::array<results::ChannelResult, model::fatigue::kMaxChannels> channels{};

  LoopCounters counters{};
};
static_assert(std::is_trivially_copyable_v<Snapshot>, "Snapshot crosses threads by copy");

/// The register values (app/results/register_map.hpp) of a snapshot.
results::ResultsValues to_results_values(const Snapshot& s);

}  // namespace app::loop
