#pragma once
// Synthetic 10-minute mean wind speeds with a site's statistics, for `drivetwin
// synth-scada` (history-mode runs over years).
//
// Marginal: Weibull(k, c), by a Gaussian copula v = c·(−ln(1 − Φ(z)))^(1/k).
// Persistence: z is the sum of two independent unit-variance AR(1) processes,
//   z_i = √w·x_i + √(1−w)·y_i,  x_i = φ_s·x_{i−1} + √(1−φ_s²)·ε_i,  y likewise with φ_f,
// so corr(z_i, z_{i+L}) = w·φ_s^L + (1−w)·φ_f^L: a slow (synoptic/diurnal) and a fast
// component. One AR(1) fitted to the lag-1 correlation alone (0.951 at Kelmarsh) forgets
// too fast: its correlation after 4 h is 0.30 where the site's is 0.60, so a day's wind
// wanders too much within the day (daily std of the 10-minute means 2.10 m/s against the
// site's 1.53 m/s) and the damage of days with a given mean wind is overstated, while the
// total over years (set by the marginal alone) is not.
//
// Defaults fitted to Kelmarsh turbine 1, January–June 2019 (shared/data/kelmarsh, Plumley
// 2022, CC-BY-4.0): k = 2.60, c = 6.73 m/s by the method of moments (mean 5.98 m/s,
// standard deviation 2.48 m/s); the two components by least squares on the correlation of
// the Gaussianised 10-minute winds z = Φ⁻¹(F_Weibull(v)) at lags 1, 2, 3, 6, 12, 24, 36, 72
// and 144 rows (inside the file's gap-free blocks), with lag 1 matched exactly:
//   measured  0.951 0.917 0.892 0.837 0.750 0.600 0.465 0.153 0.001
//   this fit  0.951 0.927 0.906 0.847 0.742 0.568 0.435 0.195 0.039
//   one AR(1) 0.951 0.904 0.860 0.740 0.547 0.299 0.164 0.027 0.000
// → slow time constant 45 rows (7.5 h, φ_s = e^(−1/45) per 10 minutes), weight w = 0.968;
// fast φ_f = 0.13 per 10 minutes. For another row period Δt the per-row coefficients are
// φ^(Δt/600 s). w = 1 with φ_s = φ gives the single AR(1).
//
// Random numbers: std::mt19937_64 (fully specified by the C++ standard) with our own
// Box–Muller transform, so a seed gives the same series on every platform.
//
// Thread context: host-side generator (no real-time use); next() allocates nothing.

#include <cstdint>
#include <random>

namespace app::wind {

struct SyntheticWindParameters {
  double weibull_k = 2.60;                   // [-] shape
  double weibull_c = 6.73;                   // [m/s] scale
  double slow_weight = 0.968;                // [-] w, share of the variance of z, (0, 1]
  double slow_time_constant_s = 45 * 600.0;  // [s] τ_s: φ_s = exp(−Δt/τ_s)
  double fast_lag1_10min = 0.13;             // [-] φ_f per 600 s, [0, 1)
};

/// Whether the parameters are usable; else *what names the offending one.
bool valid_synthetic_wind(const SyntheticWindParameters& p, double row_period_s, const char** what);

/// corr(z_i, z_{i+L}) of the model for rows `period_s` apart (for tests and reports).
double synthetic_wind_correlation(const SyntheticWindParameters& p, double period_s,
                                  double lag_rows);

/// Standard normal variates: mt19937_64 and Box–Muller (platform-independent).
class NormalSource {
 public:
  explicit NormalSource(std::uint64_t seed) : rng_(seed) {}
  double next();

 private:
  double uniform() { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; }
  std::mt19937_64 rng_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

class SyntheticWind {
 public:
  /// @param p         must satisfy valid_synthetic_wind(p, period_s)
  /// @param period_s  row period [s]
  SyntheticWind(const SyntheticWindParameters& p, double period_s, std::uint64_t seed);

  /// The next row's 10-minute mean wind [m/s], ≥ 0.
  double next();

 private:
  SyntheticWindParameters p_;
  double phi_slow_ = 0.0, phi_fast_ = 0.0;      // per row
  double innov_slow_ = 0.0, innov_fast_ = 0.0;  // √(1 − φ²)
  double x_ = 0.0, y_ = 0.0;
  bool started_ = false;
  NormalSource normal_;
};

}  // namespace app::wind
