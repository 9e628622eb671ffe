#include "model/wind/cp_surface.hpp"

#include <cmath>

namespace model::wind {

double power_coefficient(const CpSurface& surface, double tip_speed_ratio, double pitch_rad) {
  const double lambda = surface.lambda_scale * tip_speed_ratio;
  if (!(lambda > 0.0)) return 0.0;
  // Heier's coefficients expect β in degrees.
  const double beta_deg = pitch_rad * (180.0 / 3.14159265358979323846);
  const double denominator = lambda + surface.lambda_i_beta * beta_deg;
  if (!(denominator > 0.0)) return 0.0;
  // Slootweg et al. 2003, eq. 4: 1/λ_i
  const double inv_lambda_i =
      1.0 / denominator - surface.lambda_i_cubic / (beta_deg * beta_deg * beta_deg + 1.0);
  const auto& c = surface.c;
  // Slootweg et al. 2003, eq. 3 (with Heier's c6·λ term)
  const double cp = c[0] * (c[1] * inv_lambda_i - c[2] * beta_deg - c[3]) *
                        std::exp(-c[4] * inv_lambda_i) +
                    c[5] * lambda;
  return cp > 0.0 && std::isfinite(cp) ? cp : 0.0;
}

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
