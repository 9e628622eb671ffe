#pragma once
// Speed tracking without a tacho: the reference shaft's angle recovered from the
// vibration itself, from a line that is locked to the shaft (a gear-mesh harmonic),
// for recordings whose speed drifts by a few per cent.
//
//  1. Line choice: of the candidate lines (kinematic orders of the reference shaft,
//     e.g. every mesh harmonic), the one that stands highest above its surroundings in
//     a spectrum averaged over the recording, among those whose nearest kinematic
//     neighbours (sidebands) are far enough apart to be separated.
//  2. Coarse track: the line's peak in each frame of a short-time Fourier transform
//     (Hann, zero-padded ×4, parabolic interpolation of the log amplitude), searched
//     within ±search of its nominal frequency; speed = line frequency / order,
//     integrated to an angle.
//  3. Refinement by phase demodulation (Bonnardot, El Badaoui, Randall, Danière &
//     Guillet, MSSP 19 (2005) "Use of the acceleration signal of a gearbox in order to
//     perform angular resampling (with limited speed fluctuation)"): resampled on the
//     coarse angle, the line is nearly stationary; its analytic signal in a narrow band
//     (0.4 × the neighbour spacing) has the phase 2π·order·θ_true, whose difference from
//     2π·order·θ_coarse corrects the angle. Repeated `refinements` times.
// The result is a map of the reference angle against time given as the instants of
// whole revolutions (a virtual once-per-revolution tacho).
//
// Thread context: host tools and the diagnosis's low-priority thread; allocates.

#include <cstddef>
#include <vector>

#include "model/diagnosis/angle.hpp"

namespace model::diagnosis {

/// A line locked to the reference shaft.
struct LineCandidate {
  double order = 0.0;    // [cycles per reference revolution]
  double spacing = 0.0;  // [orders] distance to the nearest kinematic neighbour (sideband)
};

struct SpeedTrackingConfig {
  double search = 0.04;      // [-] relative half-width of the search window (±2 % drift + margin)
  double max_frame_s = 1.0;  // [s] longest STFT frame of the coarse track
  double band_share = 0.4;   // [-] demodulation half-band as a share of the neighbour spacing
  int refinements = 2;       // [-] phase-demodulation passes
  double min_prominence = 4.0;  // [-] line peak / median of its surroundings to be usable
};

struct TrackedSpeed {
  bool ok = false;
  AngleMap map;             // reference shaft angle
  double line_order = 0.0;  // [orders] the line followed
  double prominence = 0.0;  // [-] of that line in the averaged spectrum
  double mean_hz = 0.0;     // [Hz] reference shaft
  double min_hz = 0.0;      // [Hz] slowest revolution
  double max_hz = 0.0;      // [Hz] fastest revolution
};

/// Tracks the reference shaft's speed in x (fs_hz) around `nominal_hz` from one of the
/// candidate lines. ok = false when no candidate is usable (none prominent, all too
/// close to their neighbours for the recording's length, or above 0.45·fs).
TrackedSpeed track_speed(const double* x, std::size_t n, double fs_hz, double nominal_hz,
                         const std::vector<LineCandidate>& candidates,
                         const SpeedTrackingConfig& config = {});

}  // namespace model::diagnosis
