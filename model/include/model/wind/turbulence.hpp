#pragma once
// Turbulent hub-height wind: the random component the paper's "random wind load
// model" adds to the mean wind, here as IEC 61400-1 ed. 3 prescribes it.
//
// Normal turbulence model (IEC 61400-1:2005 §6.3.1.3):
//   σ1 = I_ref·(0.75·V_hub + b),  b = 5.6 m/s,  I_ref = 0.16 / 0.14 / 0.12 (class A / B / C)
// Kaimal longitudinal spectrum (IEC 61400-1:2005 Annex B, eq. B.14), one-sided:
//   S(f) = 4·σ1²·(L/V) / (1 + 6·f·L/V)^(5/3),  L = 8.1·Λ1,
//   Λ1 = 0.7·z for hub height z < 60 m, 42 m otherwise (§6.3, eq. 5).
//
// Series (sum of harmonics with random phases, Shinozuka & Deodatis 1991, evaluated
// by one inverse FFT): for one segment of T = n·Δt seconds (a SCADA row, 600 s)
//   u(t_j) = Σ_{k=1}^{n/2−1} a_k·cos(2π·f_k·t_j + φ_k),  f_k = k/T,
//   a_k = √(2·S(f_k)·Δf)·g,  Δf = 1/T,  φ_k uniform in [0, 2π).
// Deterministic amplitudes (as TurbSim and IEC practice use): over the segment the
// sample mean of u is exactly 0 and its variance exactly Σ a_k²/2 (the harmonics are
// orthogonal over one period). The gain g scales that variance to σ1² exactly:
// IEC's σ1 is the standard deviation within a 10-minute record, while the discrete
// spectrum from 1/T to the Nyquist frequency holds only part of the Kaimal spectrum's
// σ1² (84 % at 6.75 m/s, L/V = 50 s, T = 600 s, Δt = 0.25 s; the rest lies below
// 1/(2T), in the variation of the 10-minute means, which SCADA rows already carry).
// Turbulence is thus added INSIDE each row without changing the row's mean: the
// sequence of 10-minute means comes from the caller (SCADA file, synthetic history).
//
// Consecutive segments are independent realisations (IEC practice: one 10-minute
// simulation per mean wind). Where two rows meet, the series cross-fades over
// crossfade_s centred on the boundary (each segment continued periodically, which is
// exact for a harmonic sum): fluctuation cos(πx/2)·u_a + sin(πx/2)·u_b (variance
// preserved for independent u_a, u_b of equal σ) and mean (1−x)·V_a + x·V_b, x
// running 0 → 1 across the window; so no step of √2·σ1 at each boundary, and each
// row's mean changes only in second order (symmetric window).
//
// Rotor-effective wind (when TurbulenceSettings::rotor_radius_m > 0): the longitudinal
// wind averaged uniformly over the rotor disc. Its spectrum is S(f)·χ(f) with
//   χ(f) = ∫_0^{2R} p(d)·Coh(d, f) dd,
//   Coh(d, f) = exp(−12·√((f·d/V)² + (0.12·d/L_c)²)),  L_c = 8.1·Λ1
// (IEC 61400-1:2005 Annex B, exponential coherence model, eq. B.16) and p(d) the density of
// the distance between two points uniform on a disc of radius R ("disc line picking"):
//   p(d) = 4d/(πR²)·[acos(d/2R) − (d/2R)·√(1 − d²/4R²)].
// The point wind's gain g (above) is kept, so the averaged wind has variance
// σ1²·Σ S·χ / Σ S < σ1². The disc is weighted by area, not by each radius's share of the
// aerodynamic torque (which grows outwards and would average more), and the blades'
// rotation through the field (rotational sampling) is not modelled. With rotor_radius_m = 0
// the series is the wind at the hub point: an UPPER BOUND of the fluctuations.
//
// Random numbers: std::mt19937_64 (fully specified by the C++ standard) and our own
// conversion to [0, 1), so a seed gives the same phases on every platform.
//
// Thread context: TurbulentWind allocates its FFT plan and buffers in the constructor
// (start-up); advance() and wind_mps() then allocate nothing and throw nothing. It is an
// offline generator (synthetic SCADA), not part of the real-time loop.

#include <complex>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

namespace model::wind {

/// IEC 61400-1 ed. 3 turbulence category.
enum class TurbulenceClass : std::uint8_t { kA, kB, kC };

/// I_ref: 0.16 (A), 0.14 (B), 0.12 (C).
double reference_turbulence_intensity(TurbulenceClass turbulence_class);

/// σ1 of the normal turbulence model [m/s]: I_ref·(0.75·V + 5.6 m/s).
/// @param mean_wind_mps  10-minute mean hub-height wind V [m/s]
double ntm_sigma_mps(TurbulenceClass turbulence_class, double mean_wind_mps);

/// Kaimal integral length scale L = 8.1·Λ1 [m]; Λ1 = 0.7·z below 60 m hub height, else 42 m.
double kaimal_length_scale_m(double hub_height_m);

/// One-sided Kaimal spectrum S(f) [(m/s)²/Hz] (header).
/// @param f_hz            frequency [Hz], ≥ 0
/// @param sigma_mps       σ1 [m/s]
/// @param length_scale_m  L [m]
/// @param mean_wind_mps   V [m/s], > 0
double kaimal_psd(double f_hz, double sigma_mps, double length_scale_m, double mean_wind_mps);

struct TurbulenceSettings {
  TurbulenceClass turbulence_class = TurbulenceClass::kA;  // conservative of the three
  double hub_height_m = 80.0;     // [m] ≥ 60 m: Λ1 = 42 m (any hub of a 41 m rotor's class)
  double segment_s = 600.0;       // [s] one SCADA row
  double sample_period_s = 0.25;  // [s] Δt; Nyquist 2 Hz
  double crossfade_s = 30.0;      // [s] window centred on each row boundary
  double rotor_radius_m = 0.0;    // [m] > 0: rotor-effective wind over this disc; 0: hub point
};

/// IEC 61400-1 exponential coherence of the longitudinal wind at separation d (header).
/// @param coherence_scale_m  L_c = 8.1·Λ1 [m] (= kaimal_length_scale_m)
double iec_coherence(double separation_m, double f_hz, double mean_wind_mps,
                     double coherence_scale_m);

/// Density of the distance between two points uniform on a disc of radius R [1/m] (header).
double disc_distance_density(double distance_m, double radius_m);

/// χ(f): the disc average's share of the point spectrum at f (header), in (0, 1].
double rotor_admittance(double f_hz, double mean_wind_mps, double radius_m,
                        double coherence_scale_m);

/// Whether the settings can be generated; else *what names the offending field.
bool valid_turbulence_settings(const TurbulenceSettings& settings, const char** what);

/// Turbulent wind for a sequence of rows, one row (segment) at a time.
/// Usage: advance(V_0, V_1); read wind_mps(j) for j < samples_per_segment();
///        advance(V_1, V_2); ... A mean ≤ 0 or NaN means "no row there" (a gap, the
///        first or last row, or calm): no fluctuation and no cross-fade on that side.
class TurbulentWind {
 public:
  /// @param settings  must satisfy valid_turbulence_settings (else every wind is the mean)
  /// @param seed      random seed of the phases
  TurbulentWind(const TurbulenceSettings& settings, std::uint64_t seed);
  ~TurbulentWind();
  TurbulentWind(const TurbulentWind&) = delete;
  TurbulentWind& operator=(const TurbulentWind&) = delete;

  /// Moves to the next row: the previous current row becomes the previous one.
  /// @param current_mean_mps  mean wind of the row now current [m/s] (must equal the
  ///                          next_mean_mps of the previous call, except after a gap)
  /// @param next_mean_mps     mean wind of the row after it [m/s]; ≤ 0 or NaN: none
  void advance(double current_mean_mps, double next_mean_mps);

  /// Marks a break (a gap in time): the next advance() starts without a previous row.
  void reset_neighbours();

  /// Wind speed at sample j ∈ [0, samples_per_segment()) of the current row [m/s], ≥ 0.
  double wind_mps(std::size_t j) const;

  /// Zero-mean fluctuation of the current row alone, no cross-fade [m/s] (for tests).
  double fluctuation_mps(std::size_t j) const { return current_.u[j]; }

  std::size_t samples_per_segment() const { return n_; }
  double sample_period_s() const { return settings_.sample_period_s; }
  const TurbulenceSettings& settings() const { return settings_; }

 private:
  struct Segment {
    double mean_mps = 0.0;  // ≤ 0: no row
    std::vector<double> u;  // zero-mean fluctuation, periodic with n samples
  };
  void generate(Segment& segment, double mean_mps);
  double uniform();

  TurbulenceSettings settings_;
  std::size_t n_ = 0;     // samples per segment (even)
  std::size_t fade_ = 0;  // samples of the cross-fade on either side of a boundary
  double length_scale_m_ = 0.0;
  std::mt19937_64 rng_;
  struct Fft;
  std::unique_ptr<Fft> fft_;
  std::vector<std::complex<double>> spectrum_;
  std::vector<std::complex<double>> series_;
  Segment previous_, current_, next_;
  bool have_next_ = false;  // next_ already generated for the mean it carries
};

}  // namespace model::wind
