#pragma once
// History mode of the fatigue model: years of SCADA rows → Palmgren–Miner damage per
// gear (and failure mode) and bearing, and the remaining useful life, by interpolating a
// precomputed load spectrum (model/fatigue/load_spectrum.hpp) per row. No dynamics run
// per row.
//
// Per row: rotor torque T and speed n, then D_c += d_c(T, n)·n/60·Δt for every channel,
// Δt = the SCADA period (each row stands for one period; `--period`, or detected as the
// smallest positive time step among the first rows).
//   T: measured torque_nm if present; else P_el/(η·ω) from power_kw and rotor_speed_rpm
//      (ω > 0); else the wind load model (model/wind) from wind speed (with the measured
//      rotor speed and pitch where present, otherwise the controller's steady state).
//   n: measured rotor_speed_rpm; else the wind model's steady-state speed.
//
// Row handling (documented contract; every case is counted, the first kMaxIssues listed
// with data row number and column):
//   rejected (skipped; never touches the damage; makes the command exit non-zero):
//     a cell that is not a finite number (reported by the reader), t_s missing,
//     t_s not after the previous accepted row (duplicate or unsorted),
//     rotor_speed_rpm < −1 (negative speed; −1..0 is read as 0, sensor offset),
//     rotor_speed_rpm above 1.5 × rated, negative wind speed.
//   no data (skipped, not an error): no torque, power or wind value in the row.
//   gap (reported, not an error): t_s more than 1.5 periods after the previous row; the
//     missing time is not extrapolated (damage covers recorded time only).
//
// Thread context: non-real-time command code (allocates).

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "hal/scada_csv.hpp"
#include "model/drivetrain/description.hpp"
#include "model/fatigue/drivetrain_channels.hpp"
#include "model/fatigue/load_spectrum.hpp"
#include "model/fatigue/rul.hpp"

namespace app::fatigue {

inline constexpr std::size_t kMaxIssues = 50;
inline constexpr double kGapFactor = 1.5;          // [-] × period
inline constexpr double kSpeedOffsetRpm = 1.0;     // [rpm] negative speeds down to −1 read as 0
inline constexpr double kMaxSpeedFactor = 1.5;     // [-] × rated rotor speed
inline constexpr std::size_t kTorqueBins = 12;     // damage by torque, 0.1·rated wide, last open

struct HistoryIssue {
  std::size_t row = 0;    // data row (1 = first after the header)
  std::string field;      // column, e.g. "t_s"
  std::string message;    // full text with file, row and column
};

/// Where a row's rotor torque comes from. kAuto: the order in the file comment. The
/// others force one source (a row without it is "no data"); kWindSteady also takes the
/// rotor speed from the wind model's steady state, ignoring the measured one (to drive
/// one turbine's drivetrain with another site's wind).
enum class TorqueFrom { kAuto, kTorque, kPower, kWind, kWindSteady };

struct HistoryOptions {
  TorqueFrom torque_from = TorqueFrom::kAuto;
  double period_s = 0.0;  // [s] 0: detect
  std::size_t rul_short_window_days = 30;
  std::size_t max_rows = 0;  // stop after this many data rows (0: all)
  std::function<void(std::size_t rows)> progress;  // called every few thousand rows (may be empty)
};

struct HistoryResult {
  std::size_t rows = 0, rows_used = 0, rows_rejected = 0, rows_no_data = 0;
  std::size_t gaps = 0;
  double gap_s = 0.0;            // [s] time missing in gaps
  double period_s = 0.0;         // [s]
  double covered_s = 0.0;        // [s] rows_used × period
  double first_t_s = 0.0, last_t_s = 0.0;
  std::size_t torque_rows_measured = 0, torque_rows_power = 0, torque_rows_wind = 0;
  std::vector<double> damage;                 // per channel [-]
  std::vector<model::fatigue::RulEstimate> rul;  // per channel
  // Breakdown by rotor torque bin (0.1·rated wide) of the gear-contact channel with the largest damage:
  std::size_t breakdown_channel = 0;
  std::vector<double> bin_time_s, bin_damage;  // kTorqueBins each
  std::vector<HistoryIssue> issues;             // first kMaxIssues
  std::size_t rejected_nonnumeric = 0, rejected_time = 0, rejected_speed = 0, rejected_wind = 0;
};

/// Processes every row of an opened reader. Throws std::runtime_error only for failures
/// that stop the whole file (I/O error, no usable rows to detect the period).
HistoryResult run_history(hal::ScadaCsvReader& reader, const model::Drivetrain& drivetrain,
                          const model::fatigue::ChannelSet& channels,
                          const model::fatigue::LoadSpectrum& spectrum, const HistoryOptions& options);

}  // namespace app::fatigue
