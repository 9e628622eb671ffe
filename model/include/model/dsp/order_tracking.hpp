#pragma once
// Computed order tracking: resampling a vibration waveform from the time
// domain to the angle domain of a reference shaft (Fyfe & Munck 1997,
// "Analysis of computed order tracking", MSSP 11(2)), so that every mesh
// frequency sits on a fixed order line however the speed drifts.
//
// The shaft angle comes from, in order of preference:
//   1. a once-per-revolution tacho: pulse times from detect_pulses(), the
//      angle linear in time between consecutive pulses;
//   2. a speed (SCADA or the recording's operating point): angle = 2π·f·t;
//   3. the mesh line: estimate_shaft_hz_from_mesh() refines a nominal speed
//      from the spectral line of a known mesh order, then as 2.
//
// Thread context: construct at start-up (allocates the pulse buffer); every
// call afterwards is allocation-free and non-blocking; one owning thread.

#include <cstddef>
#include <optional>
#include <vector>

#include "model/dsp/spectrum.hpp"

namespace model::dsp {

/// Shaft angle reference for one recording.
struct SpeedReference {
  const double* pulse_times_s = nullptr;  // [s] one pulse per revolution, ascending; nullptr: none
  std::size_t pulses = 0;                 // [-] number of pulse times
  double shaft_hz = 0.0;                  // [Hz] constant speed, used when pulses < 2
};

class OrderTracker {
 public:
  /// @param samples_per_rev angle-domain samples per revolution of the reference shaft
  /// @param revolutions     revolutions per analysed block
  /// @param max_pulses      capacity for tacho pulse times; further pulses are ignored
  OrderTracker(std::size_t samples_per_rev, std::size_t revolutions, std::size_t max_pulses);

  std::size_t samples_per_rev() const { return samples_per_rev_; }
  std::size_t revolutions() const { return revolutions_; }
  /// Length of the angle-domain block [samples].
  std::size_t size() const { return samples_per_rev_ * revolutions_; }

  /// Rising crossings of the mid level of a tacho waveform, with hysteresis
  /// (re-armed only after the signal falls below a quarter of its range), each
  /// located by linear interpolation between the two samples around it.
  /// @param tacho   n samples [V]
  /// @param fs_hz   sample rate [Hz]
  /// @return number of pulse times stored (≤ max_pulses); read them with pulse_times()
  std::size_t detect_pulses(const double* tacho, std::size_t n, double fs_hz);
  const double* pulse_times() const { return pulse_times_.data(); }

  /// Resamples x to `size()` samples at uniform shaft angle, starting at the
  /// first pulse (or at t = 1/fs with a constant speed), by cubic (Catmull–Rom)
  /// interpolation in time.
  /// @param x     n samples [any unit] at fs_hz
  /// @param out   size() samples [same unit], sample j at angle j/samples_per_rev [rev]
  /// @return kTooShort when the recording does not cover `revolutions()`
  ///         revolutions, kNoSpeed without pulses or a positive speed
  DspStatus resample(const double* x, std::size_t n, double fs_hz, const SpeedReference& speed,
                     double* out) const;

 private:
  std::size_t samples_per_rev_;
  std::size_t revolutions_;
  std::vector<double> pulse_times_;  // [s] capacity max_pulses
  std::size_t max_pulses_;
};

/// Shaft speed from the mesh line: the strongest line within ±search of
/// mesh_order·nominal_shaft_hz in the spectrum of the first analyzer.size()
/// samples of x, located by the energy-weighted centroid of ±2 lines around it.
/// @param search relative half-width of the search window [-], e.g. 0.05
/// @param work   analyzer.lines() scratch values, owned by the caller
/// @return [Hz] shaft speed, or nullopt when x is shorter than the analyzer or
///         the window is outside the spectrum
std::optional<double> estimate_shaft_hz_from_mesh(const double* x, std::size_t n, double fs_hz,
                                                  double nominal_shaft_hz, double mesh_order,
                                                  double search, SpectrumAnalyzer& analyzer,
                                                  double* work);

}  // namespace model::dsp
