#pragma once
// Rotor input torque from SCADA rows: the app-side glue between hal's SCADA
// reader and model::wind::WindLoad, shared by `drivetwin torque`, `demo` and
// `fit-cp`. Rows it cannot use (unreadable, or a value beyond wind/scada_limits.hpp, the
// limits every SCADA reader uses) are rejected, counted and named by the policy every
// SCADA reader shares (wind/scada_rows.hpp) and the pass carries on; it derives the
// reference torque the
// estimate is compared with, decides which rows count as "in operation", and
// accumulates MAPE per operating region.
//
// Reference torque (what the estimate is compared with):
//   measured `torque_nm` when the row has it (compared with the rotor torque
//   estimate T), else
//   P_el / ω: measured electrical power over measured rotor speed, the measured
//   torque on the electrical side. The estimate is then converted to that side,
//   (η·T·ω − P_0)/ω (model/wind/corrections.hpp: drivetrain_efficiency η,
//   no-load loss P_0), so that the MAPE's denominator is the measurement: the
//   exact inverse of the rotor torque the power source gives everywhere else,
//   (P_el + P_0)/(η·ω) (wind/torque_source.hpp).
//
// Inflow (model::wind::Inflow): with an ambient temperature column the air
// density is ρ(T, site altitude) (model/wind/corrections.hpp), else the
// description's constant ρ; a yaw error column feeds the cos^x(γ) factor.
// Both can be switched off (EstimatorOptions) to measure what they do.
//
// Rows in operation (the only ones counted in MAPE), all of:
//   - a reference torque exists and is > 0 (generating),
//   - wind in [cut-in, cut-out) (regions 2, 2½, 3),
//   - rotor turning at ≥ 90 % of the minimum rotor speed (or ≥ 0.5 rpm when
//     the description has none): excludes stops, start-ups and shut-downs,
//   - not curtailed: pitch ≤ kCurtailPitchDeg below rated wind (a raised pitch
//     below rated is derating, curtailment or a transient), and above rated
//     wind the power ≥ kCurtailPowerFraction of rated.
//
// Thread context: non-real-time command code (allocates for messages only).

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "hal/scada_csv.hpp"
#include "model/drivetrain/description.hpp"
#include "model/wind/wind_load.hpp"
#include "wind/scada_limits.hpp"
#include "wind/scada_rows.hpp"

namespace app::wind {

inline constexpr double kCurtailPitchDeg = 3.0;       // [deg]
inline constexpr double kCurtailPowerFraction = 0.5;  // [-] of rated power, above rated wind

enum class ReferenceKind { kNone, kMeasuredTorque, kPowerOverSpeed };

struct RowEstimate {
  model::wind::WindLoadOutput load;  // meaningful only when estimated
  bool estimated = false;            // false: no wind speed in the row, no estimate (not a
                                     // region: a rotor turning at 10 rpm is not below cut-in)
  double reference_torque_nm = 0.0;  // [N·m] valid when reference != kNone
  double compared_torque_nm = 0.0;   // [N·m] the estimate on the reference's side: load.torque_nm
                                     // against torque_nm, (η·T·ω − P_0)/ω against P/ω
  double air_density_kg_m3 = 0.0;    // [kg/m³] used; from the temperature when density_measured
  bool density_measured = false;     // ρ from this row's ambient temperature
  bool yaw_measured = false;         // this row's yaw error fed the cos^x factor
  ReferenceKind reference = ReferenceKind::kNone;
  bool in_operation = false;          // counted in MAPE
  const char* excluded_because = "";  // why not in operation ("" when it is)
};

/// Which measurements the estimate uses (all that a file has, by default).
struct EstimatorOptions {
  bool measured_speed = true;        // false: the controller's steady state
  bool measured_pitch = false;       // see TorqueEstimator
  bool measured_temperature = true;  // ρ from the ambient temperature column when present
  bool measured_yaw = true;          // cos^x(yaw error) when the column is present
};

class TorqueEstimator {
 public:
  TorqueEstimator(const model::Drivetrain& drivetrain, const EstimatorOptions& options);

  /// @param use_measured_speed  false: ignore measured rotor speed / pitch and use
  ///                            the controller's steady state (for comparison)
  /// @param use_measured_pitch  feed the measured pitch into Cp(λ, β). Off by default:
  ///   the Heier surface's pitch term b/(β³+1) drops Cp by about a quarter between
  ///   0° and 2° (far more than a real blade), and a 10-min mean pitch near rated
  ///   mixes pitched and unpitched seconds; on Kelmarsh (Jan–Mar 2019) using it
  ///   raised the MAPE from 13.5 % to 14.9 %. Pitch is still used to find curtailment.
  TorqueEstimator(const model::Drivetrain& drivetrain, bool use_measured_speed,
                  bool use_measured_pitch = false);

  /// Estimates one row whose values are plausible for this turbine: run_torque() screens
  /// every row with limits() first (app/wind/scada_rows.hpp: an implausible row is
  /// counted, named and skipped, never estimated).
  void estimate(const hal::ScadaRow& row, RowEstimate& out) const;
  /// The plausibility limits of this turbine's SCADA values.
  const ScadaLimits& limits() const { return limits_; }

  const model::wind::WindLoad& load() const { return load_; }
  const EstimatorOptions& options() const { return options_; }

 private:
  model::Turbine turbine_;
  ScadaLimits limits_;
  model::wind::WindLoad load_;
  EstimatorOptions options_;
};

/// Mean absolute percentage error per region (2, 2½, 3) and overall.
class MapeAccumulator {
 public:
  static constexpr std::size_t kRegions = 3;  // 2, 2.5, 3
  void add(const RowEstimate& e);
  std::size_t count(std::size_t region) const { return count_[region]; }
  std::size_t count() const;
  double mape_pct(std::size_t region) const;
  double mape_pct() const;
  static const char* region_label(std::size_t region);

 private:
  std::array<std::size_t, kRegions> count_{};
  std::array<double, kRegions> sum_abs_pct_{};
};

/// What a pass over a SCADA file found.
struct TorqueSummary {
  std::size_t rows = 0;
  std::array<std::size_t, 6> region_rows{};  // indexed by model::wind::OperatingRegion
  std::size_t no_wind_rows = 0;              // rows without a wind speed (no estimate)
  double min_torque_nm = std::numeric_limits<double>::infinity();  // [N·m] over rows with T > 0
  double max_torque_nm = 0.0;                                      // [N·m]
  std::size_t measured_torque_rows = 0;                            // reference = measured torque_nm
  std::size_t power_rows = 0;                                      // reference = P/ω
  std::size_t density_rows = 0;  // ρ from the row's ambient temperature
  std::size_t yaw_rows = 0;      // yaw error used
  MapeAccumulator mape;
  std::vector<std::pair<std::string, std::size_t>> excluded;  // reason, rows
  RowRejections rejected;  // rows skipped: unreadable or implausible (wind/scada_rows.hpp)
  void add(const RowEstimate& e);
};

/// Calendar month 1..12 of a UTC time in seconds since 1970-01-01 (proleptic Gregorian).
int utc_month(double t_s);

/// Time window [from, to) in seconds (t_s of the file); NaN bounds are open. Only the
/// calendar months (UTC) whose bit is set in `months` (bit m − 1 for month m) are inside;
/// app/wind/heldout.hpp's MonthSet builds the mask.
struct TimeWindow {
  double from_s = std::numeric_limits<double>::quiet_NaN();
  double to_s = std::numeric_limits<double>::quiet_NaN();
  std::uint16_t months = 0x0FFF;
  bool contains(double t_s) const;
  bool restricted() const { return !std::isnan(from_s) || !std::isnan(to_s) || months != 0x0FFF; }
};

/// Streams every row of an opened reader through the estimator; rows outside
/// the window are skipped. Calls on_row (may be empty) for each estimated row. A row
/// that cannot be read, or (inside the window) holds an implausible value, is counted in
/// TorqueSummary::rejected, named and skipped. Throws std::runtime_error on an I/O error
/// and when every row of the file was rejected (nothing to report).
TorqueSummary run_torque(
    hal::ScadaCsvReader& reader, const TorqueEstimator& estimator, const TimeWindow& window,
    const std::function<void(const hal::ScadaRow&, const RowEstimate&)>& on_row);

/// Parses "YYYY-MM-DD" or "YYYY-MM-DD HH:MM:SS" (UTC) or a number of seconds.
/// Throws std::runtime_error naming the option on failure.
double parse_time_option(const std::string& option, const std::string& text);

}  // namespace app::wind
