#include "model/wind/cp_surface.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace model::wind {

namespace {

// Heier's surface at the scaled tip-speed ratio λ' (> 0).
double heier_cp(const CpSurface& surface, double lambda, double pitch_rad);

// Monotone piecewise-cubic Hermite interpolation (Fritsch & Carlson 1980) of the
// table at λ'; end values held outside the knots.
double table_cp(const CpSurface& surface, double lambda) {
  constexpr std::size_t n = kCpTableKnots;
  const auto& y = surface.table_cp;
  const double h =
      (surface.table_lambda_max - surface.table_lambda_min) / static_cast<double>(n - 1);
  if (lambda <= surface.table_lambda_min) return y[0];
  if (lambda >= surface.table_lambda_max) return y[n - 1];
  const double x = (lambda - surface.table_lambda_min) / h;
  const std::size_t k = std::min(static_cast<std::size_t>(x), n - 2);
  const double t = x - static_cast<double>(k);
  // Secant slopes (per knot spacing) and Fritsch–Carlson tangents: zero at a local
  // extremum, else the harmonic mean of the neighbouring secants (Fritsch & Butland
  // form), one-sided at the ends.
  auto secant = [&](std::size_t i) { return y[i + 1] - y[i]; };
  auto tangent = [&](std::size_t i) {
    if (i == 0) return secant(0);
    if (i == n - 1) return secant(n - 2);
    const double a = secant(i - 1);
    const double b = secant(i);
    if (a * b <= 0.0) return 0.0;
    return 2.0 * a * b / (a + b);
  };
  const double m0 = tangent(k);
  const double m1 = tangent(k + 1);
  const double t2 = t * t;
  const double t3 = t2 * t;
  // Cubic Hermite basis.
  return (2.0 * t3 - 3.0 * t2 + 1.0) * y[k] + (t3 - 2.0 * t2 + t) * m0 +
         (-2.0 * t3 + 3.0 * t2) * y[k + 1] + (t3 - t2) * m1;
}

}  // namespace

bool has_cp_table(const CpSurface& surface) {
  return surface.table_lambda_max > surface.table_lambda_min;
}

double power_coefficient(const CpSurface& surface, double tip_speed_ratio, double pitch_rad) {
  const double lambda = surface.lambda_scale * tip_speed_ratio;
  if (!(lambda > 0.0)) return 0.0;
  if (has_cp_table(surface)) {
    const double tabulated = table_cp(surface, lambda);
    if (pitch_rad == 0.0) return tabulated > 0.0 ? tabulated : 0.0;
    const double unpitched = heier_cp(surface, lambda, 0.0);
    const double ratio = unpitched > 0.0 ? heier_cp(surface, lambda, pitch_rad) / unpitched : 0.0;
    const double cp = tabulated * ratio;
    return cp > 0.0 && std::isfinite(cp) ? cp : 0.0;
  }
  return heier_cp(surface, lambda, pitch_rad);
}

namespace {

double heier_cp(const CpSurface& surface, double lambda, double pitch_rad) {
  // Heier's coefficients expect β in degrees.
  const double beta_deg = pitch_rad * (180.0 / 3.14159265358979323846);
  const double denominator = lambda + surface.lambda_i_beta * beta_deg;
  if (!(denominator > 0.0)) return 0.0;
  // Slootweg et al. 2003, eq. 4: 1/λ_i
  const double inv_lambda_i =
      1.0 / denominator - surface.lambda_i_cubic / (beta_deg * beta_deg * beta_deg + 1.0);
  const auto& c = surface.c;
  // Slootweg et al. 2003, eq. 3 (with Heier's c6·λ term)
  const double cp =
      c[0] * (c[1] * inv_lambda_i - c[2] * beta_deg - c[3]) * std::exp(-c[4] * inv_lambda_i) +
      c[5] * lambda;
  return cp > 0.0 && std::isfinite(cp) ? cp : 0.0;
}

}  // namespace

CpPeak find_cp_peak(const CpSurface& surface) {
  constexpr double kLambdaMin = 1.0;
  constexpr double kLambdaMax = 20.0;
  constexpr double kScanStep = 0.05;
  auto cp = [&](double lambda) { return power_coefficient(surface, lambda, 0.0); };

  double best_lambda = kLambdaMin;
  double best_cp = cp(kLambdaMin);
  for (double lambda = kLambdaMin + kScanStep; lambda <= kLambdaMax; lambda += kScanStep) {
    const double value = cp(lambda);
    if (value > best_cp) {
      best_cp = value;
      best_lambda = lambda;
    }
  }
  // Golden-section refinement within one scan step either side of the best sample.
  const double kInvPhi = (std::sqrt(5.0) - 1.0) / 2.0;
  double lo = best_lambda - kScanStep;
  double hi = best_lambda + kScanStep;
  double x1 = hi - kInvPhi * (hi - lo);
  double x2 = lo + kInvPhi * (hi - lo);
  double f1 = cp(x1);
  double f2 = cp(x2);
  while (hi - lo > 1e-6) {
    if (f1 < f2) {
      lo = x1;
      x1 = x2;
      f1 = f2;
      x2 = lo + kInvPhi * (hi - lo);
      f2 = cp(x2);
    } else {
      hi = x2;
      x2 = x1;
      f2 = f1;
      x1 = hi - kInvPhi * (hi - lo);
      f1 = cp(x1);
    }
  }
  const double lambda_opt = 0.5 * (lo + hi);
  const double peak = cp(lambda_opt);
  if (peak >= best_cp) return {peak, lambda_opt};
  return {best_cp, best_lambda};
}

}  // namespace model::wind
