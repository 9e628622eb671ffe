#include "model/fatigue/sn_curve.hpp"

namespace model::fatigue {

double SnCurve::knee_stress() const {
  if (!std::isfinite(knee_cycles)) return 0.0;
  return c * std::pow(knee_cycles / n_ref, -1.0 / m);
}

double SnCurve::exponent_beyond_knee() const {
  switch (branch) {
    case KneeBranch::kHaibach:
      return 2.0 * m - 1.0;  // ISO 6336-6 / Haibach: slope −1/(2m−1)
    case KneeBranch::kIsoLifeLine:
      // σ(N) = σ_k·(N/N0)^(−k) with σ(1e10) = 0.85·σ_k.
      return std::log(1e10 / knee_cycles) / std::log(1.0 / kIsoLifeFactorAt1e10);
    case KneeBranch::kNone:
      break;
  }
  return m;
}

double SnCurve::cycles_to_failure(double stress) const {
  if (!(stress > 0.0)) return std::numeric_limits<double>::infinity();
  const double n_first = n_ref * std::exp(m * std::log(c / stress));
  if (branch == KneeBranch::kNone || !std::isfinite(knee_cycles) || n_first <= knee_cycles) {
    return n_first;
  }
  return knee_cycles * std::exp(exponent_beyond_knee() * std::log(knee_stress() / stress));
}

double SnCurve::damage_per_cycle(double stress) const {
  if (!(stress > 0.0)) return 0.0;
  return 1.0 / cycles_to_failure(stress);
}

}  // namespace model::fatigue
