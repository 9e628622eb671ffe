#include "wind/cp_fit.hpp"

#include "units.hpp"

#include <unsupported/Eigen/LevenbergMarquardt>
#include <unsupported/Eigen/NumericalDiff>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <stdexcept>

#include "model/wind/cp_surface.hpp"
#include "model/wind/wind_load.hpp"

namespace app::wind {
namespace {

// Parameters: c1 (amplitude) and lambda_scale (where the peak lies); the textbook
// shape and pitch terms stay. Freeing all of c1..c6 lets least squares bend the
// surface into shapes with Cp > 1 outside the data (tried: Cp 6.6 at λ = 20);
// freeing the pitch term c3 lets it trade region 3 (few rows) for rows pitched by
// transients below rated wind (tried: c3 = 5, every region-3 estimate 0).
// The corrections FitOptions frees follow, in this order: P_0 (in kW, so that
// all parameters are of order 1 for the finite-difference Jacobian), b, x.
constexpr int kSurfaceParams = 2;
constexpr int kIrlsRounds = 8;
constexpr double kLossScaleW = 1e3;  // [W] per unit of the P_0 parameter
constexpr double kStartYawExponent = 2.0;
constexpr double kStartTrackingMargin = 0.1;       // [-] m
constexpr double kStartTurbulenceIntensity = 0.1;  // [-] I
// A weak pull of each table knot towards its textbook start value, so that a knot
// with (almost) no rows in its λ interval stays where the textbook puts it instead
// of drifting to 0 or the Betz limit: a 0.1 deviation costs about what one row with
// a 10 % error does in the IRLS objective ((0.1·3.16)² ≈ 0.1), which knots with
// data outweigh by orders of magnitude.
constexpr double kKnotPriorWeight = 3.16;

// A rotor's Cp(λ) at fixed pitch has one maximum: the knots rise up to the tracked tip-speed
// ratio and fall above it. Each step against that costs kShapeWeight per unit of Cp: a
// 0.01 wrong-way step weighs (3)² = 9 in the IRLS sum, as much as nine rows 100 % off, so on
// real data the steps come out flat rather than wrong-way (with 30 a table fitted to Kelmarsh
// still rose from 0.36 to 0.42 above λ_c and peaked at λ 11.9).
constexpr double kShapeWeight = 300.0;

int prior_count(const FitOptions& o) {
  return o.cp_table ? static_cast<int>(2 * model::kCpTableKnots - 1) : 0;
}

int surface_parameter_count(const FitOptions& o) {
  return o.cp_table ? static_cast<int>(model::kCpTableKnots) : kSurfaceParams;
}

int parameter_count(const FitOptions& o) {
  return surface_parameter_count(o) + (o.no_load_loss ? 1 : 0) + (o.nacelle_offset ? 1 : 0) +
         (o.nacelle_gain ? 1 : 0) + (o.yaw_exponent ? 1 : 0) + (o.tracking_tsr ? 1 : 0) +
         (o.tracking_band ? 1 : 0) + (o.turbulence ? 1 : 0);
}

double logistic(double q) { return 1.0 / (1.0 + std::exp(-q)); }
double logit(double y) { return std::log(y / (1.0 - y)); }

model::Turbine with_params(model::Turbine t, const FitOptions& o, const Eigen::VectorXd& p) {
  Eigen::Index i = 0;
  if (o.cp_table) {
    for (double& knot : t.cp.table_cp) knot = model::wind::kBetzLimit * logistic(p[i++]);
  } else {
    t.cp.c[0] = p[i++];
    t.cp.lambda_scale = p[i++];
  }
  if (o.no_load_loss) t.corrections.no_load_loss_w = p[i++] * kLossScaleW;
  if (o.nacelle_offset) t.corrections.nacelle_wind_offset_mps = p[i++];
  if (o.nacelle_gain) t.corrections.nacelle_wind_gain = p[i++];
  if (o.yaw_exponent) t.corrections.yaw_loss_exponent = p[i++];
  if (o.tracking_tsr) t.corrections.tracking_tip_speed_ratio = p[i++];
  if (o.tracking_band) t.corrections.tracking_band_margin = std::fabs(p[i++]);
  if (o.turbulence) t.corrections.turbulence_intensity = std::fabs(p[i++]);
  return t;
}

Eigen::VectorXd params_of(const model::Turbine& t, const FitOptions& o) {
  Eigen::VectorXd p(parameter_count(o));
  Eigen::Index i = 0;
  if (o.cp_table) {
    for (double knot : t.cp.table_cp) {
      p[i++] = logit(std::clamp(knot / model::wind::kBetzLimit, 1e-6, 1.0 - 1e-6));
    }
  } else {
    p[i++] = t.cp.c[0];
    p[i++] = t.cp.lambda_scale;
  }
  if (o.no_load_loss) p[i++] = t.corrections.no_load_loss_w / kLossScaleW;
  if (o.nacelle_offset) p[i++] = t.corrections.nacelle_wind_offset_mps;
  if (o.nacelle_gain) p[i++] = t.corrections.nacelle_wind_gain;
  if (o.yaw_exponent) p[i++] = t.corrections.yaw_loss_exponent;
  if (o.tracking_tsr) p[i++] = t.corrections.tracking_tip_speed_ratio;
  if (o.tracking_band) p[i++] = t.corrections.tracking_band_margin;
  if (o.turbulence) p[i++] = t.corrections.turbulence_intensity;
  return p;
}

struct Residuals : Eigen::DenseFunctor<double> {
  Residuals(const model::Turbine& turbine, const std::vector<FitRow>& rows,
            const FitOptions& options)
      : Eigen::DenseFunctor<double>(parameter_count(options),
                                    static_cast<int>(rows.size()) + prior_count(options)),
        turbine_(turbine),
        rows_(rows),
        options_(options) {}

  int operator()(const Eigen::VectorXd& p, Eigen::VectorXd& r) const {
    const model::wind::WindLoad load(with_params(turbine_, options_, p));
    for (std::size_t i = 0; i < rows_.size(); ++i) {
      const FitRow& row = rows_[i];
      const double torque = load.with_rotor_speed(row.wind_speed_mps, row.rotor_speed_rad_s,
                                                  row.pitch_rad, row.has_pitch, row.inflow)
                                .torque_nm;
      // The estimate on the reference's side (app/wind/torque_estimate.hpp).
      const double compared =
          row.electrical_reference
              ? load.electrical_power_w(torque, row.rotor_speed_rad_s) / row.rotor_speed_rad_s
              : torque;
      r[static_cast<Eigen::Index>(i)] =
          weight_[i] * (compared - row.reference_torque_nm) / row.reference_torque_nm;
    }
    if (options_.cp_table) {
      const model::Turbine t = with_params(turbine_, options_, p);
      for (std::size_t k = 0; k < model::kCpTableKnots; ++k) {
        r[static_cast<Eigen::Index>(rows_.size() + k)] =
            kKnotPriorWeight * (t.cp.table_cp[k] - turbine_.cp.table_cp[k]);
      }
      const double peak = t.corrections.tracking_tip_speed_ratio > 0.0
                              ? t.corrections.tracking_tip_speed_ratio
                              : model::wind::find_cp_peak(t.cp).lambda_opt;
      const double step = (t.cp.table_lambda_max - t.cp.table_lambda_min) /
                          static_cast<double>(model::kCpTableKnots - 1);
      for (std::size_t k = 0; k + 1 < model::kCpTableKnots; ++k) {
        const double rise = t.cp.table_cp[k + 1] - t.cp.table_cp[k];
        const double lambda_mid = t.cp.table_lambda_min + step * (static_cast<double>(k) + 0.5);
        const double wrong_way = lambda_mid < peak ? std::min(rise, 0.0) : std::max(rise, 0.0);
        r[static_cast<Eigen::Index>(rows_.size() + model::kCpTableKnots + k)] =
            kShapeWeight * wrong_way;
      }
    }
    return 0;
  }

  const model::Turbine& turbine_;
  const std::vector<FitRow>& rows_;
  FitOptions options_;
  std::vector<double> weight_ = std::vector<double>(rows_.size(), 1.0);
};

std::string format_double(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  std::string s(buf, r.ptr);
  if (s.find_first_of(".eE") == std::string::npos) s += ".0";
  return s;
}

}  // namespace

model::CpSurface textbook_cp_surface() {
  model::CpSurface s;
  s.c = {0.5176, 116.0, 0.4, 5.0, 21.0, 0.0068};
  s.lambda_i_beta = 0.08;
  s.lambda_i_cubic = 0.035;
  s.lambda_scale = 1.0;
  return s;
}

FitRow fit_row_of(const hal::ScadaRow& row, const RowEstimate& e) {
  FitRow r{row.get(hal::ScadaQuantity::kWindSpeed),
           row.get(hal::ScadaQuantity::kRotorSpeed) * kRpmToRadS,
           0.0,  // pitch: see TorqueEstimator (curtailment filter only)
           false,
           e.reference_torque_nm,
           e.reference == ReferenceKind::kPowerOverSpeed,
           {}};
  if (e.density_measured) r.inflow.air_density_kg_m3 = e.air_density_kg_m3;
  if (row.has(hal::ScadaQuantity::kYawError)) {
    r.inflow.yaw_error_rad = row.get(hal::ScadaQuantity::kYawError) * kDegToRad;
  }
  return r;
}

model::CpSurface textbook_cp_table(const model::Turbine& turbine) {
  model::CpSurface s = textbook_cp_surface();
  const double r = turbine.rotor_radius_m;
  s.table_lambda_min =
      0.9 * turbine.rated_rotor_speed_rpm * kRpmToRadS * r / turbine.rated_wind_mps;
  const double min_rpm = turbine.min_rotor_speed_rpm > 0.0 ? turbine.min_rotor_speed_rpm
                                                           : turbine.rated_rotor_speed_rpm;
  s.table_lambda_max = turbine.cut_in_wind_mps > 0.0
                           ? 1.1 * min_rpm * kRpmToRadS * r / turbine.cut_in_wind_mps
                           : 2.0 * s.table_lambda_min;
  model::CpSurface heier = s;
  heier.table_lambda_max = heier.table_lambda_min = 0.0;
  const double step =
      (s.table_lambda_max - s.table_lambda_min) / static_cast<double>(model::kCpTableKnots - 1);
  for (std::size_t k = 0; k < model::kCpTableKnots; ++k) {
    const double lambda = s.table_lambda_min + step * static_cast<double>(k);
    s.table_cp[k] = std::clamp(model::wind::power_coefficient(heier, lambda, 0.0), 0.01,
                               0.99 * model::wind::kBetzLimit);
  }
  return s;
}

CpFitResult fit_cp_surface(const model::Turbine& turbine, const std::vector<FitRow>& rows,
                           const FitOptions& options) {
  const int params = parameter_count(options);
  if (rows.size() < static_cast<std::size_t>(params) * 10) {
    throw std::runtime_error("fit-cp: " + std::to_string(rows.size()) +
                             " rows in operation in the fitting window; need at least " +
                             std::to_string(params * 10));
  }
  model::Turbine start = turbine;
  start.cp = options.cp_table ? textbook_cp_table(turbine) : textbook_cp_surface();
  // Corrections not freed are none (a = 1, b = 0, P_0 = 0, x = 0), whatever the
  // description holds: a re-run, or an ablation, does not inherit an earlier fit.
  start.corrections = model::TurbineCorrections{};
  if (options.yaw_exponent) start.corrections.yaw_loss_exponent = kStartYawExponent;
  if (options.tracking_tsr) {
    // A controller is designed to track the rotor's λ_opt: start from the start surface's.
    start.corrections.tracking_tip_speed_ratio = model::wind::find_cp_peak(start.cp).lambda_opt;
  }
  if (options.tracking_band) start.corrections.tracking_band_margin = kStartTrackingMargin;
  if (options.turbulence) start.corrections.turbulence_intensity = kStartTurbulenceIntensity;

  Residuals residuals(start, rows, options);
  Eigen::VectorXd p = params_of(start, options);
  const auto n = static_cast<Eigen::Index>(rows.size());
  Eigen::VectorXd r(n + prior_count(options));

  CpFitResult result;
  residuals(p, r);
  result.mean_abs_relative_error_before = r.head(n).cwiseAbs().mean();
  // L1 (the MAPE the fit is judged by) by iteratively reweighted least squares:
  // weight_i = 1/sqrt(max(|r_i|, 1e-3)) so that Σ(w_i r_i)² ≈ Σ|r_i|.
  Eigen::VectorXd best_p = p;
  double best_objective = result.mean_abs_relative_error_before;
  for (int round = 0; round < kIrlsRounds; ++round) {
    std::fill(residuals.weight_.begin(), residuals.weight_.end(), 1.0);
    residuals(p, r);
    // IRLS need not decrease the L1 objective every round: keep the best point seen.
    const double objective = r.head(n).cwiseAbs().mean();
    if (objective < best_objective) {
      best_objective = objective;
      best_p = p;
    }
    for (std::size_t i = 0; i < rows.size(); ++i) {
      residuals.weight_[i] =
          1.0 / std::sqrt(std::max(std::fabs(r[static_cast<Eigen::Index>(i)]), 1e-3));
    }
    Eigen::NumericalDiff<Residuals> numeric(residuals);
    Eigen::LevenbergMarquardt<Eigen::NumericalDiff<Residuals>> lm(numeric);
    lm.setMaxfev(2000);
    lm.setFactor(1.0);  // initial step bound: small steps keep logistic knots off saturation
    result.lm_status = static_cast<int>(lm.minimize(p));
    result.iterations += static_cast<int>(lm.iterations());
  }
  std::fill(residuals.weight_.begin(), residuals.weight_.end(), 1.0);
  residuals(p, r);
  if (!(r.head(n).cwiseAbs().mean() < best_objective)) {
    p = best_p;
    residuals(p, r);
  }
  result.mean_abs_relative_error_after = r.head(n).cwiseAbs().mean();
  const model::Turbine fitted = with_params(start, options, p);
  result.surface = fitted.cp;
  result.corrections = fitted.corrections;
  result.rows = rows.size();
  return result;
}

std::string cp_table_toml(const model::CpSurface& s) {
  std::string out = "[turbine.cp]\nc = [";
  for (std::size_t i = 0; i < s.c.size(); ++i) out += (i ? ", " : "") + format_double(s.c[i]);
  out += "]\nlambda_i_beta = " + format_double(s.lambda_i_beta) +
         "\nlambda_i_cubic = " + format_double(s.lambda_i_cubic) +
         "\nlambda_scale = " + format_double(s.lambda_scale) + "\n";
  if (model::wind::has_cp_table(s)) {
    out += "table_lambda_min = " + format_double(s.table_lambda_min) +
           "\ntable_lambda_max = " + format_double(s.table_lambda_max) + "\ntable_cp = [";
    for (std::size_t i = 0; i < s.table_cp.size(); ++i) {
      out += (i ? ", " : "") + format_double(s.table_cp[i]);
    }
    out += "]\n";
  }
  return out;
}

std::string corrections_table_toml(const model::TurbineCorrections& c) {
  return "[turbine.corrections]\nno_load_loss_w = " + format_double(c.no_load_loss_w) +
         "\nnacelle_wind_gain = " + format_double(c.nacelle_wind_gain) +
         "\nnacelle_wind_offset_mps = " + format_double(c.nacelle_wind_offset_mps) +
         "\nyaw_loss_exponent = " + format_double(c.yaw_loss_exponent) +
         "\ntracking_tip_speed_ratio = " + format_double(c.tracking_tip_speed_ratio) +
         "\ntracking_band_margin = " + format_double(c.tracking_band_margin) +
         "\nturbulence_intensity = " + format_double(c.turbulence_intensity) + "\n";
}

std::string replace_or_append_table(const std::string& text, const std::string& header,
                                    const std::string& table) {
  const std::string marker = "\n[" + header + "]";
  const std::size_t start = text.find(marker);
  if (start == std::string::npos) {
    return text + (text.empty() || text.back() == '\n' ? "\n" : "\n\n") + table;
  }
  std::size_t end = text.find("\n[", start + marker.size());
  end = end == std::string::npos ? text.size() : end + 1;
  return text.substr(0, start + 1) + table + (end < text.size() ? "\n" : "") + text.substr(end);
}

std::string replace_cp_table(const std::string& text, const std::string& table,
                             const std::string& source) {
  const std::string header = "\n[turbine.cp]";
  const std::size_t start = text.find(header);
  if (start == std::string::npos) {
    throw std::runtime_error(source + ": no [turbine.cp] table to replace");
  }
  std::size_t end = text.find("\n[", start + header.size());
  end = end == std::string::npos ? text.size() : end + 1;
  return text.substr(0, start + 1) + table + (end < text.size() ? "\n" : "") + text.substr(end);
}

}  // namespace app::wind
