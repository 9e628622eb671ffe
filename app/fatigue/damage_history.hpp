#pragma once
// History mode of the fatigue model: years of SCADA rows → Palmgren–Miner damage per
// gear (and failure mode) and bearing, and the remaining useful life, by interpolating a
// precomputed load spectrum (model/fatigue/load_spectrum.hpp) per row. No dynamics run
// per row.
//
// Per row: rotor torque T and speed n, then D_c += d_c(T, n)·n/60·Δt for every channel,
// Δt = the SCADA period (each row stands for one period; `--period`, or detected as the
// smallest positive time step among the first rows).
//   T, n: app/wind/torque_source.hpp, the one torque source of the project: measured
//      torque_nm if present; else (P_el + P_0)/(η·ω) from power_kw and rotor_speed_rpm;
//      else the wind load model (model/wind) from wind speed (with the measured rotor
//      speed and pitch where present, otherwise the controller's steady state, which then
//      also gives n).
//
// Row handling (documented contract; every case is counted, the first kMaxIssues listed
// with data row number and column):
//   rejected (skipped; never touches the damage; makes the command exit non-zero):
//     a cell that is not a finite number (reported by the reader), t_s missing,
//     t_s not after the previous accepted row (duplicate or unsorted),
//     any value outside its plausibility limit (app/wind/scada_limits.hpp: e.g. rotor
//     speed below −1 or above 1.5 × rated, negative wind speed, power beyond twice rated),
//     a rotor torque or speed beyond the load spectrum's grid (torque above 1.5 × rated:
//     its damage cannot be interpolated, and clamping it to the edge would hide a torque
//     column in the wrong unit; counted as rejected_spectrum, the largest such torque kept).
//   A file with no data row, or none usable, is an error (nothing is accumulated).
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
#include "wind/scada_rows.hpp"
#include "wind/torque_source.hpp"

namespace app::fatigue {

inline constexpr std::size_t kMaxIssues = app::wind::kMaxScadaIssues;
inline constexpr double kGapFactor = 1.5;       // [-] × period
inline constexpr std::size_t kTorqueBins = 12;  // damage by torque, 0.1·rated wide, last open

using HistoryIssue = app::wind::ScadaIssue;

/// Where a row's rotor torque comes from (app/wind/torque_source.hpp).
using TorqueFrom = app::wind::TorquePreference;

struct HistoryOptions {
  TorqueFrom torque_from = TorqueFrom::kAuto;
  double period_s = 0.0;  // [s] 0: detect
  std::size_t rul_short_window_days = 30;
  std::size_t max_rows = 0;  // stop after this many data rows (0: all)
  bool per_day = false;      // also record the damage of every UTC day (HistoryResult::days)
  std::function<void(std::size_t rows)> progress;  // called every few thousand rows (may be empty)
  /// When set, a row's damage per rotor revolution comes from this evaluation at the row's
  /// exact (torque [N·m], speed [rpm]) instead of the spectrum's interpolation (`damage
  /// --spectrum dynamics-rows`); a false return skips the row as one without data.
  std::function<bool(double torque_nm, double rotor_rpm, double* damage_per_rev)> at_point;
};

/// One UTC day of the history (rows with t_s in [day·86 400, (day+1)·86 400)).
struct DayRecord {
  long long day = 0;           // [d] floor(t_s / 86 400): days since the epoch of t_s
  double covered_s = 0.0;      // [s] used rows × period
  double wind_sum_mps = 0.0;   // [m/s] sum of the used rows' wind speed
  std::size_t wind_rows = 0;   // [-] used rows with a wind speed
  std::vector<double> damage;  // [-] per channel, that day's damage
  double mean_wind_mps() const {
    return wind_rows ? wind_sum_mps / static_cast<double>(wind_rows) : 0.0;
  }
};

/// The rows rejected (rows_rejected, rejected_* by reason, the listed `issues`: also the
/// gaps) come from app/wind/scada_rows.hpp, the policy every SCADA reader shares.
struct HistoryResult : app::wind::RowRejections {
  std::size_t rows = 0, rows_used = 0, rows_no_data = 0;
  std::size_t gaps = 0;
  double gap_s = 0.0;      // [s] time missing in gaps
  double period_s = 0.0;   // [s]
  double covered_s = 0.0;  // [s] rows_used × period
  double first_t_s = 0.0, last_t_s = 0.0;
  std::size_t torque_rows_measured = 0, torque_rows_power = 0, torque_rows_wind = 0;
  std::vector<double> damage;                    // per channel [-]
  std::vector<model::fatigue::RulEstimate> rul;  // per channel
  // Breakdown by rotor torque bin (0.1·rated wide) of the gear-contact channel with the largest
  // damage:
  std::size_t breakdown_channel = 0;
  std::vector<double> bin_time_s, bin_damage;  // kTorqueBins each
  std::vector<DayRecord> days;          // per UTC day with data, when HistoryOptions::per_day
  std::size_t rejected_spectrum = 0;    // torque or speed beyond the load spectrum's grid
  double max_rejected_torque_nm = 0.0;  // [N·m] largest torque among those
  std::vector<double> exceeded_at_s;    // per channel: t_s of the row where D reached 1 (NaN: not)
};

/// Order statistics of a sample. Quantiles interpolate linearly between order statistics
/// (Hyndman–Fan type 7: q(p) at rank (n − 1)·p). All zero when count is 0.
struct Quantiles {
  std::size_t count = 0;
  double min = 0.0, q1 = 0.0, median = 0.0, q3 = 0.0, max = 0.0, mean = 0.0;
};
Quantiles quantiles(std::vector<double> sample);

/// Distribution of one channel's damage over the full days (covered_s ≥ full_day_s) of a
/// history, and over those full days whose mean wind is within ±band_mps of wind_ref_mps
/// (the paper's one-day figure is the damage of a day at its check point's wind).
struct DayDistribution {
  std::size_t full_days = 0, partial_days = 0;
  Quantiles all;  // [-] damage per day of every full day (all.count == full_days)
  std::vector<std::size_t>
      nearest;  // indices into the days vector: full days by |mean wind − wind_ref|, closest first
  Quantiles band;  // [-] damage per day of the full days with |mean wind − wind_ref| ≤ band_mps
};
DayDistribution day_distribution(const std::vector<DayRecord>& days, std::size_t channel,
                                 double full_day_s, double wind_ref_mps, std::size_t nearest_count,
                                 double band_mps = 0.1);

/// The (torque, speed) grid of the quasi-static spectrum: torque to 1.5·rated, rotor speed
/// 0.5 rpm to 1.2·rated (at least 1 rpm), the node counts of SpectrumGrid's defaults.
model::fatigue::SpectrumGrid quasi_static_grid(const model::Drivetrain& drivetrain);

/// Processes every row of an opened reader. Throws std::runtime_error only for failures
/// that stop the whole file (I/O error, no usable rows to detect the period).
HistoryResult run_history(hal::ScadaCsvReader& reader, const model::Drivetrain& drivetrain,
                          const model::fatigue::ChannelSet& channels,
                          const model::fatigue::LoadSpectrum& spectrum,
                          const HistoryOptions& options);

}  // namespace app::fatigue
