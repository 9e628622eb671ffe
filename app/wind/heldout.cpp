#include "wind/heldout.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace app::wind {
namespace {

constexpr std::array<const char*, 12> kMonthNames{"Jan", "Feb", "Mar", "Apr", "May", "Jun",
                                                  "Jul", "Aug", "Sep", "Oct", "Nov", "Dec"};
constexpr std::uint16_t kAllMonths = 0x0FFF;

std::uint16_t bit(int month) { return static_cast<std::uint16_t>(1u << (month - 1)); }

// Region slot of MapeAccumulator (0: 2, 1: 2½, 2: 3), or -1.
int region_slot(model::wind::OperatingRegion r) {
  switch (r) {
    case model::wind::OperatingRegion::kTracking:
      return 0;
    case model::wind::OperatingRegion::kSpeedLimited:
      return 1;
    case model::wind::OperatingRegion::kRated:
      return 2;
    default:
      return -1;
  }
}

// "%.2f" (signed: "%+.2f") of v, or "–" when it is not finite.
std::string fmt2(double v, bool show_sign = false) {
  if (!std::isfinite(v)) return "–";
  char buf[32];
  std::snprintf(buf, sizeof buf, show_sign ? "%+.2f" : "%.2f", v);
  return buf;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

bool parse_month(const std::string& text, int* month) {
  if (text.empty() || text.size() > 2) return false;
  int v = 0;
  for (char c : text) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + (c - '0');
  }
  if (v < 1 || v > 12) return false;
  *month = v;
  return true;
}

// "<MAPE> (<rows>)" or "–".
std::string mape_cell(const ErrorCell& c) {
  if (c.rows == 0) return "–";
  return fmt2(c.mape_pct()) + " (" + std::to_string(c.rows) + ")";
}

}  // namespace

MonthSet MonthSet::of(std::initializer_list<int> months) {
  std::uint16_t bits = 0;
  for (int m : months) {
    if (m >= 1 && m <= 12) bits |= bit(m);
  }
  return MonthSet(bits);
}

std::optional<MonthSet> MonthSet::parse(const std::string& text, std::string* error) {
  std::uint16_t bits = 0;
  std::stringstream in(text);
  std::string item;
  bool any = false;
  while (std::getline(in, item, ',')) {
    item = trim(item);
    any = true;
    if (item == "DJF") {
      bits |= bit(12) | bit(1) | bit(2);
      continue;
    }
    if (item == "MAM") {
      bits |= bit(3) | bit(4) | bit(5);
      continue;
    }
    if (item == "JJA") {
      bits |= bit(6) | bit(7) | bit(8);
      continue;
    }
    if (item == "SON") {
      bits |= bit(9) | bit(10) | bit(11);
      continue;
    }
    const auto dash = item.find('-');
    int a = 0, b = 0;
    if (dash == std::string::npos) {
      if (!parse_month(item, &a)) {
        if (error) {
          *error = "'" + item + "' is not a month 1..12 or a season DJF, MAM, JJA, SON";
        }
        return std::nullopt;
      }
      bits |= bit(a);
      continue;
    }
    if (!parse_month(trim(item.substr(0, dash)), &a) ||
        !parse_month(trim(item.substr(dash + 1)), &b) || a > b) {
      if (error) {
        *error = "'" + item +
                 "' is not a month range a-b with 1 <= a <= b <= 12 (a range across the year "
                 "end is written as two: 11-12,1-2)";
      }
      return std::nullopt;
    }
    for (int m = a; m <= b; ++m) bits |= bit(m);
  }
  if (!any || bits == 0) {
    if (error) *error = "no month given (expected e.g. 1-3, 4-12, 12,1,2 or DJF)";
    return std::nullopt;
  }
  return MonthSet(bits);
}

std::string MonthSet::label() const {
  if (bits_ == kAllMonths) return "all months";
  std::string out;
  int m = 1;
  while (m <= 12) {
    if (!contains(m)) {
      ++m;
      continue;
    }
    int end = m;
    while (end < 12 && contains(end + 1)) ++end;
    if (!out.empty()) out += ",";
    out += kMonthNames[static_cast<std::size_t>(m - 1)];
    if (end > m) {
      out += std::string(end > m + 1 ? "-" : ",") + kMonthNames[static_cast<std::size_t>(end - 1)];
    }
    m = end + 1;
  }
  return out;
}

std::vector<NamedMonthSet> meteorological_seasons() {
  return {{"DJF", MonthSet::of({12, 1, 2})},
          {"MAM", MonthSet::of({3, 4, 5})},
          {"JJA", MonthSet::of({6, 7, 8})},
          {"SON", MonthSet::of({9, 10, 11})}};
}

std::vector<NamedMonthSet> single_months() {
  std::vector<NamedMonthSet> out;
  for (int m = 1; m <= 12; ++m) {
    out.push_back({kMonthNames[static_cast<std::size_t>(m - 1)], MonthSet::of({m})});
  }
  return out;
}

double ErrorCell::mape_pct() const {
  return rows ? sum_abs_pct / static_cast<double>(rows) : std::nan("");
}
double ErrorCell::bias_pct() const {
  return rows ? sum_pct / static_cast<double>(rows) : std::nan("");
}

namespace {
void merge(ErrorCell& into, const ErrorCell& c) {
  into.rows += c.rows;
  into.sum_abs_pct += c.sum_abs_pct;
  into.sum_pct += c.sum_pct;
}
}  // namespace

void ErrorBreakdown::add(double t_s, double wind_speed_mps, const RowEstimate& e) {
  if (!e.in_operation) return;
  const int slot = region_slot(e.load.region);
  if (slot < 0 || !(std::fabs(e.reference_torque_nm) > 0.0)) return;
  const double error_pct =
      100.0 * (e.compared_torque_nm - e.reference_torque_nm) / std::fabs(e.reference_torque_nm);
  const int month = utc_month(t_s);
  const auto m = static_cast<std::size_t>(month - 1);
  by_month_region_[m][static_cast<std::size_t>(slot)].add(error_pct);
  if (wind_speed_mps >= 0.0 && wind_speed_mps < static_cast<double>(kWindBins)) {
    by_wind_[static_cast<std::size_t>(wind_speed_mps)].add(error_pct);
  }
  if (wind_speed_mps >= kLowWindFromMps && wind_speed_mps < kLowWindToMps) {
    low_wind_[m].add(error_pct);
  }
}

ErrorCell ErrorBreakdown::month_total(int month) const {
  ErrorCell c;
  for (const ErrorCell& r : by_month_region_[static_cast<std::size_t>(month - 1)]) merge(c, r);
  return c;
}

ErrorCell ErrorBreakdown::region_total(std::size_t region) const {
  ErrorCell c;
  for (const auto& month : by_month_region_) merge(c, month[region]);
  return c;
}

ErrorCell ErrorBreakdown::total() const {
  ErrorCell c;
  for (const auto& month : by_month_region_) {
    for (const ErrorCell& r : month) merge(c, r);
  }
  return c;
}

ErrorCell ErrorBreakdown::low_wind_total() const {
  ErrorCell c;
  for (const ErrorCell& r : low_wind_) merge(c, r);
  return c;
}

std::string ErrorBreakdown::month_table() const {
  std::string out =
      "| month | region 2 | region 2½ | region 3 | all | bias all | 3–5 m/s | bias 3–5 m/s |\n"
      "|---|---|---|---|---|---|---|---|\n";
  auto line = [&](const std::string& label, const ErrorCell& r2, const ErrorCell& r25,
                  const ErrorCell& r3, const ErrorCell& all, const ErrorCell& low) {
    out += "| " + label + " | " + mape_cell(r2) + " | " + mape_cell(r25) + " | " + mape_cell(r3) +
           " | " + mape_cell(all) + " | " + fmt2(all.bias_pct(), true) + " | " + mape_cell(low) +
           " | " + fmt2(low.bias_pct(), true) + " |\n";
  };
  for (int m = 1; m <= 12; ++m) {
    const ErrorCell all = month_total(m);
    if (all.rows == 0) continue;
    line(kMonthNames[static_cast<std::size_t>(m - 1)], cell(m, 0), cell(m, 1), cell(m, 2), all,
         low_wind(m));
  }
  line("**all**", region_total(0), region_total(1), region_total(2), total(), low_wind_total());
  return out +
         "(MAPE % (rows); bias = mean signed error %, negative: estimate below the "
         "measurement)\n";
}

std::string ErrorBreakdown::wind_table() const {
  std::string out = "| wind (m/s) | rows | MAPE | bias |\n|---|---|---|---|\n";
  for (std::size_t b = 0; b < kWindBins; ++b) {
    const ErrorCell& c = by_wind_[b];
    if (c.rows == 0) continue;
    out += "| " + std::to_string(b) + "–" + std::to_string(b + 1) + " | " + std::to_string(c.rows) +
           " | " + fmt2(c.mape_pct()) + " | " + fmt2(c.bias_pct(), true) + " |\n";
  }
  return out;
}

TorqueSummary evaluate_scada(const std::string& path, const hal::ScadaColumns& columns,
                             const model::Drivetrain& drivetrain, const EstimatorOptions& options,
                             const TimeWindow& window, ErrorBreakdown* breakdown,
                             std::vector<FitRow>* fit_rows) {
  hal::ScadaCsvReader reader;
  if (!reader.open(path, columns)) throw std::runtime_error(reader.error());
  const TorqueEstimator estimator(drivetrain, options);
  return run_torque(reader, estimator, window, [&](const hal::ScadaRow& row, const RowEstimate& e) {
    if (breakdown) {
      breakdown->add(row.time_s(), row.get(hal::ScadaQuantity::kWindSpeed), e);
    }
    if (fit_rows && e.in_operation) fit_rows->push_back(fit_row_of(row, e));
  });
}

std::vector<FoldResult> leave_one_out(const std::string& path, const hal::ScadaColumns& columns,
                                      const model::Drivetrain& drivetrain,
                                      const EstimatorOptions& options, const TimeWindow& base,
                                      const std::vector<NamedMonthSet>& folds,
                                      const FitOptions& fit_options) {
  std::vector<FoldResult> out;
  for (const NamedMonthSet& fold : folds) {
    FoldResult r;
    r.name = fold.name;
    TimeWindow fit_window = base;
    fit_window.months = static_cast<std::uint16_t>(base.months & fold.months.complement().mask());
    TimeWindow test_window = base;
    test_window.months = static_cast<std::uint16_t>(base.months & fold.months.mask());
    r.test_months = fold.months;
    std::vector<FitRow> rows;
    evaluate_scada(path, columns, drivetrain, options, fit_window, nullptr, &rows);
    r.fit = fit_cp_surface(drivetrain.turbine, rows, fit_options);
    model::Drivetrain fitted = drivetrain;
    fitted.turbine.cp = r.fit.surface;
    fitted.turbine.corrections = r.fit.corrections;
    r.fit_rows = r.fit.rows;
    r.fit_mape_pct = evaluate_scada(path, columns, fitted, options, fit_window, nullptr, nullptr)
                         .mape.mape_pct();
    r.test = evaluate_scada(path, columns, fitted, options, test_window, &r.breakdown, nullptr);
    out.push_back(std::move(r));
  }
  return out;
}

std::string leave_one_out_table(const std::vector<FoldResult>& folds) {
  std::string out =
      "| test fold | fit rows | fit MAPE | region 2 | region 2½ | region 3 | all | bias | 3–5 m/s "
      "|\n"
      "|---|---|---|---|---|---|---|---|---|\n";
  std::array<ErrorCell, ErrorBreakdown::kRegions> regions{};
  ErrorCell all, low;
  for (const FoldResult& f : folds) {
    const ErrorBreakdown& b = f.breakdown;
    out += "| " + f.name + " (" + f.test_months.label() + ") | " + std::to_string(f.fit_rows) +
           " | " + fmt2(f.fit_mape_pct) + " | " + mape_cell(b.region_total(0)) + " | " +
           mape_cell(b.region_total(1)) + " | " + mape_cell(b.region_total(2)) + " | " +
           mape_cell(b.total()) + " | " + fmt2(b.total().bias_pct(), true) + " | " +
           mape_cell(b.low_wind_total()) + " |\n";
    for (std::size_t r = 0; r < regions.size(); ++r) merge(regions[r], b.region_total(r));
    merge(all, b.total());
    merge(low, b.low_wind_total());
  }
  out += "| **every fold's test rows** | | | " + mape_cell(regions[0]) + " | " +
         mape_cell(regions[1]) + " | " + mape_cell(regions[2]) + " | " + mape_cell(all) + " | " +
         fmt2(all.bias_pct(), true) + " | " + mape_cell(low) + " |\n";
  return out;
}

}  // namespace app::wind
