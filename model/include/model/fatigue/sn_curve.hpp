#pragma once
// S-N (Wöhler) curves for Palmgren–Miner damage.
//
//   N(σ) = N_ref·(C/σ)^m                      for N ≤ N0 (below the knee: slope −1/m in log σ–log
//   N) beyond the knee N0, σ_k = C·(N0/N_ref)^(−1/m):
//     kHaibach:      N = N0·(σ_k/σ)^(2m−1)    (ISO 6336-6 Annex / paper: slope −1/(2m−1))
//     kIsoLifeLine:  N = N0·(σ_k/σ)^(1/k), k = ln(1/0.85)/ln(1e10/N0): the ISO 6336-2/-3 life
//                    factor line (Z_NT, Y_NT falling to 0.85 at 1e10), extrapolated beyond 1e10
//     kNone:         the first branch continues (no knee; ISO 281 bearing life has none)
// Gears: N_ref = 1, σ in MPa. Bearings (ISO 281): σ = P [N], C = C_r [N], m = p, N_ref = 1e6.
//
// Thread context: pure value type; damage_per_cycle() is allocation-free (one log, one exp).

#include <cmath>
#include <limits>

namespace model::fatigue {

enum class KneeBranch { kHaibach, kIsoLifeLine, kNone };

struct SnCurve {
  double m = 0.0;      // [-] slope exponent below the knee
  double c = 0.0;      // [MPa or N] strength at N_ref cycles
  double n_ref = 1.0;  // [-] cycles at which σ = C
  double knee_cycles = std::numeric_limits<double>::infinity();  // [-] N0
  KneeBranch branch = KneeBranch::kHaibach;

  /// Stress at the knee σ_k [MPa or N].
  double knee_stress() const;
  /// Exponent beyond the knee (2m−1 for Haibach; 1/k for the ISO line; m for none).
  double exponent_beyond_knee() const;
  /// Cycles to failure at stress σ; +inf for σ ≤ 0.
  double cycles_to_failure(double stress) const;
  /// 1/N(σ), 0 for σ ≤ 0.
  double damage_per_cycle(double stress) const;
};

/// ISO 6336-2/-3 life-factor ratio at 1e10 cycles used by KneeBranch::kIsoLifeLine.
inline constexpr double kIsoLifeFactorAt1e10 = 0.85;

}  // namespace model::fatigue
