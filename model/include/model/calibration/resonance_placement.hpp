#pragma once
// Placing a resonance the local fit cannot move (issue 12).
//
// The planetary stage's torsional mode — the carrier turning against the intermediate shaft —
// has the sun shaft's torsional stiffness as its spring: on paper-2mw 118.7 Hz at the
// description's stiffness, 149.5 Hz at ×2, 179.3 Hz at ×4 (eigen-solutions of the full model),
// while ×2 on the planetary mesh, the planet bearings or the ring's torsional support moves it
// by 1–2 % (docs/calibration.md, Session 14). The reference fixes no shaft dimension, so that
// stiffness G·J/L between the sun and g1 is known only to ~×/÷ 3 (effective diameter ×/÷ 1.3
// with bore and splines, d⁴; torsional length ×/÷ 1.5): a recording's planetary mode may sit
// anywhere in ×/÷ 9 of it (2σ).
//
// Fitted from the prior, it does not get there. The lines the mode lifts are high
// planetary-mesh harmonics that the tones do not compare, and the spectral residual over them
// is not monotonic in the stiffness (each line peaks as the mode crosses it and falls beyond),
// so the trust region, which is local, keeps the mode where the prior put it; tried as a fitted
// variable from the prior (σ = ln 3, ×/÷ 9, branch sunshaft-fitted-exp), it also gave the fit a
// freedom to trade the residual for the tones on recordings whose mode was already right
// (rated-3's residual 0.70 → 1.48).
//
// So it is first placed, then fitted: after the fit, the stiffness scale is set to each of
// kPlacementPoints values — the log-centres of as many equal intervals of prior ×/÷ 9 (0.141 …
// 7.05 of the prior, ×1.63 apart, the prior itself among them) — with every other parameter at
// its fitted value, and the residual of each is computed. Where the lowest falls below the
// fitted one by more than `threshold` (the command passes 0: the other variables were fitted
// under the first mode, so the fall is a lower bound on what a refit gains), the fit runs again
// from there with the scale released (CalibrationSpace::with_sun_shaft_torsion: a variable
// centred on the description), and the better of the two fits is kept (keep_refit()).
//
// Thread context: pure functions; the caller's `residual` simulates (non-real-time).

#include <array>
#include <cmath>
#include <cstddef>

#include "model/calibration/calibrator.hpp"
#include "model/drivetrain/description.hpp"

namespace model::calibration {

inline constexpr std::size_t kPlacementPoints = 9;
inline constexpr double kPlacementRange = 9.0;  // [-] the scan spans prior ×/÷ this

struct PlacementScan {
  double prior = 0.0;                               // the description's sun_shaft_torsion_scale
  double fitted = 0.0;                              // the scale of the fit (the prior's)
  double fitted_residual = 0.0;                     // [-] the residual at the fit
  std::array<double, kPlacementPoints> value{};     // the grid
  std::array<double, kPlacementPoints> residual{};  // [-] the residual at each grid value
  double best = 0.0;                                // the scale of the lowest residual
  double best_residual = 0.0;                       // [-]
  bool refit = false;  // best_residual < fitted_residual − threshold: fit again at `best`
};

/// Scans sun_shaft_torsion_scale over prior ×/÷ kPlacementRange at the other values of
/// `fitted`. `residual(const DynamicsParameters&) -> double` is the quantity the placement
/// lowers (the unclipped spectral residual summed over the recordings); `threshold` [-] the
/// fall that warrants a refit (> 0).
template <class Residual>
PlacementScan scan_placement(const DynamicsParameters& prior, const DynamicsParameters& fitted,
                             double threshold, Residual&& residual) {
  PlacementScan s;
  s.prior = prior.sun_shaft_torsion_scale;
  s.fitted = fitted.sun_shaft_torsion_scale;
  s.fitted_residual = residual(fitted);
  s.best = s.fitted;
  s.best_residual = s.fitted_residual;
  const double lower = s.prior / kPlacementRange;
  for (std::size_t g = 0; g < kPlacementPoints; ++g) {
    const double t = (static_cast<double>(g) + 0.5) / static_cast<double>(kPlacementPoints);
    DynamicsParameters p = fitted;
    p.sun_shaft_torsion_scale = lower * std::pow(kPlacementRange * kPlacementRange, t);
    s.value[g] = p.sun_shaft_torsion_scale;
    // The grid point the fit sits on (the prior, when the fit left the scale there) is the
    // fit itself: its residual is the fitted one, not a rounding-different simulation of it.
    const bool at_fit = std::abs(s.value[g] - s.fitted) <= 1e-9 * s.fitted;
    s.residual[g] = at_fit ? s.fitted_residual : residual(p);
    if (s.residual[g] < s.best_residual) {
      s.best_residual = s.residual[g];
      s.best = s.value[g];
    }
  }
  s.refit = s.fitted_residual - s.best_residual > threshold;
  return s;
}

/// Of the first fit and the refit from the scan's best point: of two that calibrate (every
/// indicator within its threshold, nothing at a bound), the lower residual; otherwise
/// choose_space()'s rule, the refit in the richer's place — the one that calibrates, else the
/// lower worst indicator/threshold. true: the refit.
inline bool keep_refit(bool first_calibrates, double first_residual, double first_worst,
                       bool refit_calibrates, double refit_residual, double refit_worst) {
  if (first_calibrates && refit_calibrates) return refit_residual < first_residual;
  return choose_space({first_calibrates, first_worst}, {refit_calibrates, refit_worst}) ==
         SpaceChoice::kRicher;
}

}  // namespace model::calibration
