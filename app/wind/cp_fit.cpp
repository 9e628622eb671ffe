#include "wind/cp_fit.hpp"

#include <unsupported/Eigen/LevenbergMarquardt>
#include <unsupported/Eigen/NumericalDiff>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <stdexcept>

#include "model/wind/wind_load.hpp"

namespace app::wind {
namespace {

// Parameters: c1 (amplitude) and lambda_scale (where the peak lies); the textbook
// shape and pitch terms stay. Freeing all of c1..c6 lets least squares bend the
// surface into shapes with Cp > 1 outside the data (tried: Cp 6.6 at λ = 20);
// freeing the pitch term c3 lets it trade region 3 (few rows) for rows pitched by
// transients below rated wind (tried: c3 = 5, every region-3 estimate 0).
constexpr int kParams = 2;
constexpr int kIrlsRounds = 8;

model::CpSurface with_params(model::CpSurface s, const Eigen::VectorXd& p) {
  s.c[0] = p[0];
  s.lambda_scale = p[1];
  return s;
}

Eigen::VectorXd params_of(const model::CpSurface& s) {
  Eigen::VectorXd p(kParams);
  p << s.c[0], s.lambda_scale;
  return p;
}

struct Residuals : Eigen::DenseFunctor<double> {
  Residuals(const model::Turbine& turbine, const std::vector<FitRow>& rows)
      : Eigen::DenseFunctor<double>(kParams, static_cast<int>(rows.size())),
        turbine_(turbine),
        rows_(rows) {}

  int operator()(const Eigen::VectorXd& p, Eigen::VectorXd& r) const {
    model::Turbine t = turbine_;
    t.cp = with_params(t.cp, p);
    const model::wind::WindLoad load(t);
    for (std::size_t i = 0; i < rows_.size(); ++i) {
      const FitRow& row = rows_[i];
      const double torque =
          load.with_rotor_speed(row.wind_speed_mps, row.rotor_speed_rad_s, row.pitch_rad,
                                row.has_pitch)
              .torque_nm;
      r[static_cast<Eigen::Index>(i)] =
          weight_[i] * (torque - row.reference_torque_nm) / row.reference_torque_nm;
    }
    return 0;
  }

  const model::Turbine& turbine_;
  const std::vector<FitRow>& rows_;
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

CpFitResult fit_cp_surface(const model::Turbine& turbine, const std::vector<FitRow>& rows) {
  if (rows.size() < static_cast<std::size_t>(kParams) * 10) {
    throw std::runtime_error("fit-cp: " + std::to_string(rows.size()) +
                             " rows in operation in the fitting window; need at least " +
                             std::to_string(kParams * 10));
  }
  model::Turbine start = turbine;
  const model::CpSurface textbook = textbook_cp_surface();
  start.cp = textbook;

  Residuals residuals(start, rows);
  Eigen::VectorXd p = params_of(start.cp);
  Eigen::VectorXd r(static_cast<Eigen::Index>(rows.size()));

  CpFitResult result;
  residuals(p, r);
  result.mean_abs_relative_error_before = r.cwiseAbs().mean();
  // L1 (the MAPE the fit is judged by) by iteratively reweighted least squares:
  // weight_i = 1/sqrt(max(|r_i|, 1e-3)) so that Σ(w_i r_i)² ≈ Σ|r_i|.
  for (int round = 0; round < kIrlsRounds; ++round) {
    std::fill(residuals.weight_.begin(), residuals.weight_.end(), 1.0);
    residuals(p, r);
    for (std::size_t i = 0; i < rows.size(); ++i) {
      residuals.weight_[i] = 1.0 / std::sqrt(std::max(std::fabs(r[static_cast<Eigen::Index>(i)]), 1e-3));
    }
    Eigen::NumericalDiff<Residuals> numeric(residuals);
    Eigen::LevenbergMarquardt<Eigen::NumericalDiff<Residuals>> lm(numeric);
    lm.setMaxfev(2000);
    result.lm_status = static_cast<int>(lm.minimize(p));
    result.iterations += static_cast<int>(lm.iterations());
  }
  std::fill(residuals.weight_.begin(), residuals.weight_.end(), 1.0);
  residuals(p, r);
  result.mean_abs_relative_error_after = r.cwiseAbs().mean();
  result.surface = with_params(start.cp, p);
  result.rows = rows.size();
  return result;
}

std::string cp_table_toml(const model::CpSurface& s) {
  std::string out = "[turbine.cp]\nc = [";
  for (std::size_t i = 0; i < s.c.size(); ++i) out += (i ? ", " : "") + format_double(s.c[i]);
  out += "]\nlambda_i_beta = " + format_double(s.lambda_i_beta) +
         "\nlambda_i_cubic = " + format_double(s.lambda_i_cubic) +
         "\nlambda_scale = " + format_double(s.lambda_scale) + "\n";
  return out;
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
