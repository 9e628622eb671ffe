#pragma once
// Amplitude of one spectral line of a sampled signal: a Hann-windowed discrete-time
// Fourier transform evaluated at the exact frequency (not at the nearest FFT bin),
// so signals sampled at different rates compare line by line. Used to compare the
// reduced and full models and to check the kinematics of simulated spectra.
//
// Thread context: any; no allocation; O(samples) per call.

#include <cstddef>
#include <span>

namespace model::dynamics {

/// Peak amplitude [signal unit] of the component at `frequency_hz` of `x` sampled at
/// `sample_rate_hz`, mean removed. For x = A·cos(2πft + φ) + c over many periods: ≈ A.
double line_amplitude(std::span<const double> x, double sample_rate_hz, double frequency_hz);

/// Root mean square of x − mean(x) [signal unit].
double rms_about_mean(std::span<const double> x);

/// Mean of x.
double mean(std::span<const double> x);

}  // namespace model::dynamics
