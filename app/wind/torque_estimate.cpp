#include "wind/torque_estimate.hpp"

#include "units.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <stdexcept>

#include "model/wind/corrections.hpp"

namespace app::wind {
namespace {
using hal::ScadaQuantity;
using model::wind::OperatingRegion;

}  // namespace

TorqueEstimator::TorqueEstimator(const model::Drivetrain& drivetrain, bool use_measured_speed,
                                 bool use_measured_pitch)
    : TorqueEstimator(drivetrain, EstimatorOptions{use_measured_speed, use_measured_pitch}) {}

TorqueEstimator::TorqueEstimator(const model::Drivetrain& drivetrain,
                                 const EstimatorOptions& options)
    : turbine_(drivetrain.turbine),
      limits_(drivetrain),
      load_(drivetrain.turbine),
      options_(options) {}

void TorqueEstimator::estimate(const hal::ScadaRow& row, RowEstimate& out) const {
  out = RowEstimate{};
  const bool has_wind = row.has(ScadaQuantity::kWindSpeed);
  const double wind = row.get(ScadaQuantity::kWindSpeed);
  const bool has_speed = row.has(ScadaQuantity::kRotorSpeed);
  const double rpm = row.get(ScadaQuantity::kRotorSpeed);
  const bool has_pitch = row.has(ScadaQuantity::kPitch);
  const double pitch_deg = row.get(ScadaQuantity::kPitch);
  const bool has_power = row.has(ScadaQuantity::kPower);
  const double power_kw = row.get(ScadaQuantity::kPower);
  const bool has_temperature = row.has(ScadaQuantity::kAmbientTemperature);
  const double temperature_c = row.get(ScadaQuantity::kAmbientTemperature);
  const bool has_yaw = row.has(ScadaQuantity::kYawError);
  const double yaw_deg = row.get(ScadaQuantity::kYawError);
  if (!has_wind) {
    out.excluded_because = "no wind speed";
    return;
  }
  out.estimated = true;

  const double speed_rad_s = std::max(0.0, rpm) * kRpmToRadS;
  model::wind::Inflow inflow;
  out.air_density_kg_m3 = turbine_.air_density_kg_m3;
  if (options_.measured_temperature && has_temperature) {
    inflow.air_density_kg_m3 =
        model::wind::air_density_kg_m3(temperature_c, turbine_.site_altitude_m);
    out.air_density_kg_m3 = inflow.air_density_kg_m3;
    out.density_measured = true;
  }
  if (options_.measured_yaw && has_yaw && turbine_.corrections.yaw_loss_exponent > 0.0) {
    inflow.yaw_error_rad = yaw_deg * kDegToRad;
    out.yaw_measured = true;
  }
  if (options_.measured_speed && has_speed) {
    const bool pitch = options_.measured_pitch && has_pitch;
    out.load = load_.with_rotor_speed(wind, speed_rad_s, pitch ? pitch_deg * kDegToRad : 0.0, pitch,
                                      inflow);
  } else {
    out.load = load_.steady_state(wind);
    out.density_measured = false;
    out.yaw_measured = false;
    out.air_density_kg_m3 = turbine_.air_density_kg_m3;
  }

  // Reference torque, and the estimate on the same side of the drivetrain.
  if (row.has(ScadaQuantity::kRotorTorque)) {
    out.reference = ReferenceKind::kMeasuredTorque;
    out.reference_torque_nm = row.get(ScadaQuantity::kRotorTorque);
    out.compared_torque_nm = out.load.torque_nm;
  } else if (has_power && has_speed && speed_rad_s > 0.0) {
    out.reference = ReferenceKind::kPowerOverSpeed;
    out.reference_torque_nm = power_kw * 1e3 / speed_rad_s;
    // Electrical-side torque at the measured speed: (η·T·ω − P_0)/ω.
    out.compared_torque_nm =
        load_.electrical_power_w(out.load.torque_nm, speed_rad_s) / speed_rad_s;
  }

  // In operation?
  const OperatingRegion region = load_.region_of(wind);
  const double min_rpm =
      turbine_.min_rotor_speed_rpm > 0.0 ? 0.9 * turbine_.min_rotor_speed_rpm : 0.5;
  if (out.reference == ReferenceKind::kNone) {
    out.excluded_because = "no reference torque";
  } else if (region == OperatingRegion::kBelowCutIn || region == OperatingRegion::kAboveCutOut) {
    out.excluded_because = "wind outside cut-in..cut-out";
  } else if (!has_speed || rpm < min_rpm) {
    out.excluded_because = "rotor stopped or below minimum speed";
  } else if (!(out.reference_torque_nm > 0.0)) {
    out.excluded_because = "not generating";
  } else if (has_pitch && wind < turbine_.rated_wind_mps && pitch_deg > kCurtailPitchDeg) {
    out.excluded_because = "curtailed (pitch raised below rated wind)";
  } else if (has_power && wind >= turbine_.rated_wind_mps &&
             power_kw * 1e3 < kCurtailPowerFraction * turbine_.rated_power_w) {
    out.excluded_because = "curtailed (power below half rated above rated wind)";
  } else {
    out.in_operation = true;
  }
}

void MapeAccumulator::add(const RowEstimate& e) {
  if (!e.in_operation) return;
  std::size_t region = 0;
  switch (e.load.region) {
    case OperatingRegion::kTracking:
      region = 0;
      break;
    case OperatingRegion::kSpeedLimited:
      region = 1;
      break;
    case OperatingRegion::kRated:
      region = 2;
      break;
    default:
      return;  // stopped although "in operation" cannot happen: speed filter above
  }
  ++count_[region];
  sum_abs_pct_[region] += 100.0 * std::fabs(e.compared_torque_nm - e.reference_torque_nm) /
                          std::fabs(e.reference_torque_nm);
}

std::size_t MapeAccumulator::count() const { return count_[0] + count_[1] + count_[2]; }

double MapeAccumulator::mape_pct(std::size_t region) const {
  return count_[region] ? sum_abs_pct_[region] / static_cast<double>(count_[region]) : std::nan("");
}

double MapeAccumulator::mape_pct() const {
  const std::size_t n = count();
  return n ? (sum_abs_pct_[0] + sum_abs_pct_[1] + sum_abs_pct_[2]) / static_cast<double>(n)
           : std::nan("");
}

const char* MapeAccumulator::region_label(std::size_t region) {
  static constexpr const char* kLabels[kRegions] = {"2", "2.5", "3"};
  return kLabels[region];
}

void TorqueSummary::add(const RowEstimate& e) {
  ++rows;
  if (e.estimated) {
    ++region_rows[static_cast<std::size_t>(e.load.region)];
  } else {
    ++no_wind_rows;
  }
  if (e.load.torque_nm > 0.0) {
    min_torque_nm = std::min(min_torque_nm, e.load.torque_nm);
    max_torque_nm = std::max(max_torque_nm, e.load.torque_nm);
  }
  if (e.reference == ReferenceKind::kMeasuredTorque) ++measured_torque_rows;
  if (e.reference == ReferenceKind::kPowerOverSpeed) ++power_rows;
  if (e.density_measured) ++density_rows;
  if (e.yaw_measured) ++yaw_rows;
  mape.add(e);
  if (!e.in_operation) {
    for (auto& [reason, count] : excluded) {
      if (reason == e.excluded_because) {
        ++count;
        return;
      }
    }
    excluded.emplace_back(e.excluded_because, 1);
  }
}

int utc_month(double t_s) {
  // Days since 1970-01-01 to the civil date (H. Hinnant, "chrono-Compatible Low-Level Date
  // Algorithms", civil_from_days): only the month is needed.
  const auto days = static_cast<long long>(std::floor(t_s / 86400.0));
  const long long z = days + 719468;
  const long long era = (z >= 0 ? z : z - 146096) / 146097;
  const long long doe = z - era * 146097;                                       // [0, 146096]
  const long long yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;  // [0, 399]
  const long long doy = doe - (365 * yoe + yoe / 4 - yoe / 100);                // [0, 365]
  const long long mp = (5 * doy + 2) / 153;  // [0, 11], March = 0
  return static_cast<int>(mp < 10 ? mp + 3 : mp - 9);
}

bool TimeWindow::contains(double t_s) const {
  if (!std::isnan(from_s) && !(t_s >= from_s)) return false;
  if (!std::isnan(to_s) && !(t_s < to_s)) return false;
  if (months != 0x0FFF && !((months >> (utc_month(t_s) - 1)) & 1u)) return false;
  return true;
}

TorqueSummary run_torque(
    hal::ScadaCsvReader& reader, const TorqueEstimator& estimator, const TimeWindow& window,
    const std::function<void(const hal::ScadaRow&, const RowEstimate&)>& on_row) {
  TorqueSummary summary;
  hal::ScadaRow row;
  RowEstimate estimate;
  std::size_t read = 0;  // data rows read, rejected ones included
  for (;;) {
    const hal::ScadaReadResult r = reader.next(row);
    if (r == hal::ScadaReadResult::kEnd) break;
    ++read;
    if (r == hal::ScadaReadResult::kError) {
      summary.rejected.unreadable(reader, read);  // counted and named; throws on an I/O error
      continue;
    }
    if (row.has_time() && !window.contains(row.time_s())) continue;
    if (!row.has_time() && window.restricted()) {
      continue;
    }
    if (!summary.rejected.plausible(estimator.limits(), reader, row)) continue;
    estimator.estimate(row, estimate);
    summary.add(estimate);
    if (on_row) on_row(row, estimate);
  }
  if (read > 0 && summary.rejected.rows_rejected == read) {
    std::string listed;
    for (const ScadaIssue& i : summary.rejected.issues) listed += "; " + i.message;
    throw std::runtime_error(reader.path() + ": none of the " + std::to_string(read) +
                             " data rows is usable (" + summary.rejected.summary() + ")" + listed);
  }
  return summary;
}

double parse_time_option(const std::string& option, const std::string& text) {
  if (auto t = hal::parse_utc_datetime_s(text)) return *t;
  if (auto t = hal::parse_utc_datetime_s(text + " 00:00:00")) return *t;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (!text.empty() && end == text.c_str() + text.size() && std::isfinite(v)) return v;
  throw std::runtime_error(option + ": '" + text +
                           "' is not a time (expected YYYY-MM-DD, YYYY-MM-DD HH:MM:SS or seconds)");
}

}  // namespace app::wind
