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
// Annual and diurnal cycles: the Weibull scale is multiplied by
//   (1 + a_s·cos(2π(d − d_s)/365.25))·(1 + a_d·cos(2π(h − h_d)/24)),
// d the day of the year (days since 1 January, UTC), h the hour of the day (UTC), so the
// mean wind follows both first harmonics and the within-row distribution keeps its shape.
//
// Defaults fitted to Kelmarsh turbine 1 2019, days 1–6 of every month (shared/data/kelmarsh/
// kelmarsh-t1-2019.csv, Plumley 2022, CC-BY-4.0) by tools/wind_floor/fit_synthetic_wind.py:
// the annual harmonic through the twelve monthly means (a_s = 0.103, peak on day 28.8, late
// January; six days a month, so it is mostly the weather of those days: a long record would
// pin it better), the diurnal one through the hour-of-day means of the wind divided by its
// month's mean (a_d = 0.022, peak at 17:26 UTC: weak at this hub height), k = 2.666 and
// c = 6.733 m/s by the method of moments on the wind with both cycles divided out, and the
// two persistence components by least squares on the correlation of the Gaussianised
// residual z = Φ⁻¹(F_Weibull(v/cycles)) at lags 1, 2, 3, 6, 12, 24, 36, 72, 144, 288 and 432
// rows (pairs exactly that far apart, inside the six-day blocks), lag 1 matched exactly:
//   measured  0.954 0.924 0.903 0.857 0.790 0.677 0.576 0.379 0.172 0.238 0.042
//   this fit  0.954 0.917 0.887 0.824 0.754 0.669 0.599 0.431 0.223 0.059 0.016
// → slow time constant 109 rows (18.2 h, φ_s = e^(−1/109) per 10 minutes), weight w = 0.834;
// fast φ_f = 0.77 per 10 minutes. For another row period Δt the per-row coefficients are
// φ^(Δt/600 s). w = 1 with φ_s = φ gives the single AR(1). (The previous fit, on the file
// whose month and day were swapped, joined unrelated days into its "gap-free blocks" and found
// a 7.5-h time constant: its days wandered 1.81 m/s within the day against the site's 1.53.)
//
// Random numbers: std::mt19937_64 (fully specified by the C++ standard) with our own
// Box–Muller transform, so a seed gives the same series on every platform.
//
// Thread context: host-side generator (no real-time use); next() allocates nothing.

#include <cstdint>
#include <random>

namespace app::wind {

struct SyntheticWindParameters {
  double weibull_k = 2.666;                   // [-] shape
  double weibull_c = 6.733;                   // [m/s] scale (cycles divided out)
  double slow_weight = 0.834;                 // [-] w, share of the variance of z, (0, 1]
  double slow_time_constant_s = 109 * 600.0;  // [s] τ_s: φ_s = exp(−Δt/τ_s)
  double fast_lag1_10min = 0.77;              // [-] φ_f per 600 s, [0, 1)
  double seasonal_amplitude = 0.103;          // [-] a_s, [0, 1)
  double seasonal_peak_day = 28.8;            // [days since 1 January] d_s
  double diurnal_amplitude = 0.022;           // [-] a_d, [0, 1)
  double diurnal_peak_hour = 17.44;           // [h, UTC] h_d
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

  /// The next row's 10-minute mean wind [m/s], ≥ 0, for a row at `t_s` [s since 1970 UTC]
  /// (its annual and diurnal cycle).
  double next(double t_s);

  /// The factor the cycles put on the Weibull scale at `t_s` (for tests and reports).
  double cycle_factor(double t_s) const;

 private:
  SyntheticWindParameters p_;
  double phi_slow_ = 0.0, phi_fast_ = 0.0;      // per row
  double innov_slow_ = 0.0, innov_fast_ = 0.0;  // √(1 − φ²)
  double x_ = 0.0, y_ = 0.0;
  bool started_ = false;
  NormalSource normal_;
};

}  // namespace app::wind
