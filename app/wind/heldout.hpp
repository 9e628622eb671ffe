#pragma once
// Held-out tests of the wind load model with the seasons in them (`drivetwin fit-cp
// --fit-months/--test-months/--breakdown/--leave-one-out`, `drivetwin torque --breakdown`).
//
// A fair test of a model fitted to SCADA fits on some calendar months and tests on the
// others, so that what changes with the season (air density, icing, stable nights,
// turbulence) is part of the test (shared/data/README.md). This file holds
//   - MonthSet: a set of calendar months (UTC) parsed from "1-3", "4-12", "12,1,2" or a
//     meteorological season "DJF", "MAM", "JJA", "SON" (also combined: "DJF,MAM");
//   - ErrorBreakdown: the relative error of the estimate on the reference's side
//     (app/wind/torque_estimate.hpp) over rows in operation, per month × region, per
//     wind-speed bin and for the low-wind rows, as MAPE and as mean signed error (bias:
//     negative = the estimate is below the measurement);
//   - leave_one_out(): for each fold (a MonthSet) fit on the rows of every other fold and
//     test on the fold's rows, with the same fit options as the main fit.
//
// Thread context: command code (allocates).

#include <array>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

#include "hal/scada_csv.hpp"
#include "model/drivetrain/description.hpp"
#include "wind/cp_fit.hpp"
#include "wind/torque_estimate.hpp"

namespace app::wind {

/// A set of calendar months.
class MonthSet {
 public:
  /// Every month.
  static MonthSet all() { return MonthSet(0x0FFF); }
  /// Parses a comma-separated list of months (1..12), ranges "a-b" (a ≤ b) and seasons
  /// DJF / MAM / JJA / SON; empty or malformed text returns nullopt with *error saying why.
  static std::optional<MonthSet> parse(const std::string& text, std::string* error);
  /// The set with exactly these months (1..12).
  static MonthSet of(std::initializer_list<int> months);

  bool contains(int month) const {
    return month >= 1 && month <= 12 && ((bits_ >> (month - 1)) & 1u) != 0;
  }
  bool empty() const { return bits_ == 0; }
  bool is_all() const { return bits_ == 0x0FFF; }
  MonthSet complement() const { return MonthSet(static_cast<std::uint16_t>(~bits_ & 0x0FFF)); }
  bool operator==(const MonthSet& o) const { return bits_ == o.bits_; }
  MonthSet operator&(const MonthSet& o) const { return MonthSet(bits_ & o.bits_); }
  /// Bit m − 1 set for month m: TimeWindow::months.
  std::uint16_t mask() const { return bits_; }
  /// "Jan-Mar", "Dec,Jan,Feb" style label (months in calendar order, runs collapsed).
  std::string label() const;

 private:
  explicit MonthSet(std::uint16_t bits) : bits_(bits) {}
  std::uint16_t bits_ = 0;
};

/// The four meteorological seasons (DJF, MAM, JJA, SON) with their names.
struct NamedMonthSet {
  std::string name;
  MonthSet months;
};
std::vector<NamedMonthSet> meteorological_seasons();
/// Twelve folds of one month each ("Jan" .. "Dec").
std::vector<NamedMonthSet> single_months();

/// Relative errors [%] of one group of rows.
struct ErrorCell {
  std::size_t rows = 0;
  double sum_abs_pct = 0.0;
  double sum_pct = 0.0;
  void add(double error_pct) {
    ++rows;
    sum_abs_pct += error_pct < 0.0 ? -error_pct : error_pct;
    sum_pct += error_pct;
  }
  double mape_pct() const;  // NaN when empty
  double bias_pct() const;  // mean signed error, NaN when empty
};

/// Errors of the rows in operation by month × region, by wind-speed bin, and of the
/// low-wind band [kLowWindFromMps, kLowWindToMps) by month.
class ErrorBreakdown {
 public:
  static constexpr std::size_t kRegions = MapeAccumulator::kRegions;  // 2, 2½, 3
  static constexpr std::size_t kWindBins = 25;                        // 1 m/s bins, 0..25 m/s
  static constexpr double kLowWindFromMps = 3.0;
  static constexpr double kLowWindToMps = 5.0;

  /// Adds a row if it is in operation (others are ignored). The error is
  /// 100·(compared − reference)/|reference|, the MAPE's own definition.
  void add(double t_s, double wind_speed_mps, const RowEstimate& e);

  const ErrorCell& cell(int month, std::size_t region) const {
    return by_month_region_[static_cast<std::size_t>(month - 1)][region];
  }
  ErrorCell month_total(int month) const;
  ErrorCell region_total(std::size_t region) const;
  ErrorCell total() const;
  const ErrorCell& wind_bin(std::size_t bin) const { return by_wind_[bin]; }
  const ErrorCell& low_wind(int month) const {
    return low_wind_[static_cast<std::size_t>(month - 1)];
  }
  ErrorCell low_wind_total() const;

  /// Text tables: per month × region (MAPE, rows, bias, low-wind band) and per wind bin.
  std::string month_table() const;
  std::string wind_table() const;

 private:
  std::array<std::array<ErrorCell, kRegions>, 12> by_month_region_{};
  std::array<ErrorCell, kWindBins> by_wind_{};
  std::array<ErrorCell, 12> low_wind_{};
};

/// One pass of a description over a SCADA file restricted to `window` (times and
/// months), returning the summary and filling `breakdown` (may be null) and the rows in
/// operation as fitting rows (may be null). Throws std::runtime_error on bad input.
TorqueSummary evaluate_scada(const std::string& path, const hal::ScadaColumns& columns,
                             const model::Drivetrain& drivetrain, const EstimatorOptions& options,
                             const TimeWindow& window, ErrorBreakdown* breakdown,
                             std::vector<FitRow>* fit_rows);

/// One fold of a leave-one-out test.
struct FoldResult {
  std::string name;
  MonthSet test_months = MonthSet::all();
  std::size_t fit_rows = 0;
  CpFitResult fit;            // the fold's fit
  double fit_mape_pct = 0.0;  // over the fitting months, fitted description
  TorqueSummary test;         // over the fold's months, fitted description
  ErrorBreakdown breakdown;   // of the test rows
};

/// Leave-one-out over `folds`: for each fold, fit `drivetrain`'s Cp surface and the
/// corrections `fit_options` frees on the rows of `base` outside the fold, then test on the
/// rows of `base` inside it. `base` restricts both (e.g. to a year); its months are
/// intersected with each side.
std::vector<FoldResult> leave_one_out(const std::string& path, const hal::ScadaColumns& columns,
                                      const model::Drivetrain& drivetrain,
                                      const EstimatorOptions& options, const TimeWindow& base,
                                      const std::vector<NamedMonthSet>& folds,
                                      const FitOptions& fit_options);

/// Text table of leave-one-out results: one line per fold (rows, MAPE per region, all,
/// the low-wind band, bias) and the pooled line over every fold's test rows.
std::string leave_one_out_table(const std::vector<FoldResult>& folds);

}  // namespace app::wind
