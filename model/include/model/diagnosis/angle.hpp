#pragma once
// The angle domain: a reference shaft's angle as a function of time, computed order
// tracking of a waveform onto it (Fyfe & Munck, MSSP 11 (1997)), and time-synchronous
// averages per shaft with their residual and difference signals (Stewart 1977; McFadden,
// MSSP 1 (1987); Lebold, McClintic, Campbell, Byington & Maynard, "Review of vibration
// analysis methods for gearbox diagnostics and prognostics", 54th MFPT (2000)).
//
// Thread context: host tools and the diagnosis's low-priority thread; allocates.

#include <cstddef>
#include <vector>

#include "model/diagnosis/signal.hpp"

namespace model::diagnosis {

/// The reference shaft's angle [revolutions] against time [s], from the instants at
/// which it completes whole revolutions (a once-per-revolution tacho, or the crossings
/// of a tracked angle): revolution i at instant i, linear in between, extrapolated
/// with the first and last periods outside.
class AngleMap {
 public:
  AngleMap() = default;
  /// At least two strictly increasing instants [s]; otherwise valid() is false.
  static AngleMap from_pulses(std::vector<double> pulse_times_s);
  /// A constant speed [Hz] with revolution 0 at t0_s.
  static AngleMap constant(double shaft_hz, double t0_s = 0.0);

  bool valid() const { return pulses_.size() >= 2; }
  /// [rev] angle at time t_s.
  double revolutions_at(double t_s) const;
  /// [s] time of angle `revolutions` (inverse of revolutions_at).
  double time_at(double revolutions) const;
  /// [Hz] mean speed between the first and last instants.
  double mean_hz() const;
  /// The instants of whole revolutions [s].
  const std::vector<double>& pulses() const { return pulses_; }

 private:
  std::vector<double> pulses_;
};

/// Resamples x (fs_hz, n samples) at `spr` samples per revolution of a shaft turning
/// `ratio` times the reference (shaft revolutions = ratio × reference revolutions),
/// over `revs` shaft revolutions starting at shaft angle `start_rev`, by cubic
/// (Catmull–Rom) interpolation. Returns false (out untouched) when the span leaves x.
/// x should hold no content above spr·f_shaft/2 (low-pass it first otherwise).
bool resample_to_angle(const double* x, std::size_t n, double fs_hz, const AngleMap& map,
                       double ratio, double start_rev, std::size_t spr, std::size_t revs,
                       std::vector<double>& out);

/// Whole shaft revolutions of x available from shaft angle `start_rev` (≥ 0).
std::size_t revolutions_available(std::size_t n, double fs_hz, const AngleMap& map, double ratio,
                                  double start_rev);

/// An order spectrum: the Hann amplitude spectrum of `revs` revolutions of a shaft in
/// the angle domain; line k is at order k/revs (cycles per revolution of that shaft).
struct OrderSpectrum {
  std::size_t revolutions = 0;      // [-] R: resolution 1/R order
  std::size_t samples_per_rev = 0;  // [-]
  double shaft_hz = 0.0;            // [Hz] mean speed of the shaft (orders → Hz)
  std::vector<double> amplitude;    // [unit of x] per line
  double line(double order) const { return order * static_cast<double>(revolutions); }
  /// Tone amplitude at `order` (main-lobe energy, ±2 lines).
  double tone(double order) const;
  /// The local noise floor a tone at `order` is compared with.
  double noise(double order) const;
};

/// Order spectrum of `revs` revolutions (chosen 2·3·5-smooth by the caller for speed).
bool order_spectrum(const double* x, std::size_t n, double fs_hz, const AngleMap& map, double ratio,
                    double start_rev, std::size_t spr, std::size_t revs, OrderSpectrum& out);

/// A time-synchronous average and the signals separated from it.
struct SynchronousAverage {
  std::size_t samples_per_rev = 0;  // [-]
  std::size_t revolutions = 0;      // [-] averaged
  std::vector<double> average;      // [unit of x] one revolution
  std::vector<double> residual;     // average − shaft orders ≤ low_orders − mesh harmonics
  std::vector<double> difference;   // residual − the first sidebands of every mesh harmonic
  WaveformStatistics average_stats;
  WaveformStatistics residual_stats;
  WaveformStatistics difference_stats;  // its kurtosis is FM4 (Stewart 1977)
};

struct SeparationSpec {
  std::vector<int> mesh_orders;  // [-] tooth counts of the gears on the shaft (mesh orders)
  int low_orders = 3;            // [-] shaft orders 1..low_orders removed from the residual
  int sidebands = 1;             // [-] sidebands ±1..sidebands removed from the difference
};

/// Synchronous average of x over `revs` revolutions of a shaft turning `ratio` × the
/// reference, from `start_rev`, at `spr` samples per revolution (a power of two), with
/// the residual and difference signals of `spec`.
bool synchronous_average(const double* x, std::size_t n, double fs_hz, const AngleMap& map,
                         double ratio, double start_rev, std::size_t spr, std::size_t revs,
                         const SeparationSpec& spec, SynchronousAverage& out);

}  // namespace model::diagnosis
