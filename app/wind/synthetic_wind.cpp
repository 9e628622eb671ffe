#include "wind/synthetic_wind.hpp"

#include <algorithm>
#include <cmath>

namespace app::wind {
namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kTenMinutesS = 600.0;
constexpr double kDayS = 86400.0;
constexpr double kYearDays = 365.25;
}  // namespace

bool valid_synthetic_wind(const SyntheticWindParameters& p, double row_period_s,
                          const char** what) {
  const char* bad = nullptr;
  if (!(p.weibull_k > 0.0) || !std::isfinite(p.weibull_k)) {
    bad = "weibull_k must be > 0";
  } else if (!(p.weibull_c > 0.0) || !std::isfinite(p.weibull_c)) {
    bad = "weibull_c must be > 0";
  } else if (!(p.slow_weight > 0.0 && p.slow_weight <= 1.0)) {
    bad = "slow_weight must be in (0, 1]";
  } else if (!(p.slow_time_constant_s > 0.0) || !std::isfinite(p.slow_time_constant_s)) {
    bad = "slow_time_constant_s must be > 0";
  } else if (!(p.fast_lag1_10min >= 0.0 && p.fast_lag1_10min < 1.0)) {
    bad = "fast_lag1_10min must be in [0, 1)";
  } else if (!(p.seasonal_amplitude >= 0.0 && p.seasonal_amplitude < 1.0)) {
    bad = "seasonal_amplitude must be in [0, 1)";
  } else if (!std::isfinite(p.seasonal_peak_day)) {
    bad = "seasonal_peak_day must be finite";
  } else if (!(p.diurnal_amplitude >= 0.0 && p.diurnal_amplitude < 1.0)) {
    bad = "diurnal_amplitude must be in [0, 1)";
  } else if (!std::isfinite(p.diurnal_peak_hour)) {
    bad = "diurnal_peak_hour must be finite";
  } else if (!(row_period_s > 0.0) || !std::isfinite(row_period_s)) {
    bad = "the row period must be > 0";
  }
  if (what != nullptr) *what = bad;
  return bad == nullptr;
}

double synthetic_wind_correlation(const SyntheticWindParameters& p, double period_s,
                                  double lag_rows) {
  const double phi_s = std::exp(-period_s / p.slow_time_constant_s);
  const double phi_f = std::pow(p.fast_lag1_10min, period_s / kTenMinutesS);
  return p.slow_weight * std::pow(phi_s, lag_rows) +
         (1.0 - p.slow_weight) * std::pow(phi_f, lag_rows);
}

double NormalSource::next() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  double u1 = uniform();
  while (u1 <= 0.0) u1 = uniform();
  const double u2 = uniform();
  const double r = std::sqrt(-2.0 * std::log(u1));
  spare_ = r * std::sin(2.0 * kPi * u2);
  has_spare_ = true;
  return r * std::cos(2.0 * kPi * u2);
}

SyntheticWind::SyntheticWind(const SyntheticWindParameters& p, double period_s, std::uint64_t seed)
    : p_(p),
      phi_slow_(std::exp(-period_s / p.slow_time_constant_s)),
      phi_fast_(std::pow(p.fast_lag1_10min, period_s / kTenMinutesS)),
      innov_slow_(std::sqrt(1.0 - phi_slow_ * phi_slow_)),
      innov_fast_(std::sqrt(1.0 - phi_fast_ * phi_fast_)),
      normal_(seed) {}

double SyntheticWind::cycle_factor(double t_s) const {
  const double day = std::fmod(t_s / kDayS, kYearDays);  // days since 1 January (mean calendar)
  const double hour = 24.0 * (t_s / kDayS - std::floor(t_s / kDayS));
  return (1.0 +
          p_.seasonal_amplitude * std::cos(2.0 * kPi * (day - p_.seasonal_peak_day) / kYearDays)) *
         (1.0 + p_.diurnal_amplitude * std::cos(2.0 * kPi * (hour - p_.diurnal_peak_hour) / 24.0));
}

double SyntheticWind::next(double t_s) {
  if (!started_) {
    x_ = normal_.next();
    y_ = normal_.next();
    started_ = true;
  } else {
    x_ = phi_slow_ * x_ + innov_slow_ * normal_.next();
    y_ = phi_fast_ * y_ + innov_fast_ * normal_.next();
  }
  const double z = std::sqrt(p_.slow_weight) * x_ + std::sqrt(1.0 - p_.slow_weight) * y_;
  const double u = 0.5 * std::erfc(-z / std::sqrt(2.0));  // Φ(z)
  return p_.weibull_c * cycle_factor(t_s) *
         std::pow(-std::log1p(-std::min(u, 1.0 - 1e-16)), 1.0 / p_.weibull_k);
}

}  // namespace app::wind
