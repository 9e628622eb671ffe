#pragma once
// The similarity indicators of the source paper (VBDM-DT §2.3.2, §3.2,
// Table 3), computed per measurement point from the features of a simulated
// and a measured waveform (model/dsp/mesh_features.hpp).
//
// With RMS_s, RMS_m the RMS of the simulated and measured time waveforms and
// A_s,i, A_m,i (i = 1..n) the amplitudes of the fundamental and harmonics of
// every mesh frequency:
//
//   f1 = |RMS_s − RMS_m| / RMS_m
//        The paper says only that f1 is built from the two RMS values; its exact
//        formula could not be found, so this is our choice: the natural
//        relative error of the RMS.
//   f2 = 1 − ρ(A_s, A_m),   ρ = Σ(A_s,i − Ā_s)(A_m,i − Ā_m)
//                               / sqrt(Σ(A_s,i − Ā_s)² · Σ(A_m,i − Ā_m)²)
//        (Pearson correlation coefficient of the two amplitude vectors)
//   f3 = 1/n · Σ |A_s,i − A_m,i| / A_m,i        (mean absolute percentage error,
//        as a fraction, not ×100)
//
// The sums of f2 and f3 run over the tones the measurement resolves above its
// noise floor (PointFeatures::resolved of the measured point; a tone buried
// in noise carries no information about the model, and its "amplitude" would
// only measure the noise). This skip is ours, not the paper's; the number of
// tones used is reported in Indicators::tones.
//
// Thresholds (paper): f1 ≤ 0.5, f2 ≤ 0.2, f3 ≤ 0.2. A point "fits" when all
// three are at or below their thresholds.
//
// Thread context: pure functions, allocation-free, any thread.

#include <array>
#include <cstddef>

#include "model/dsp/mesh_features.hpp"

namespace model::calibration {

inline constexpr double kF1Threshold = 0.5;
inline constexpr double kF2Threshold = 0.2;
inline constexpr double kF3Threshold = 0.2;

struct Indicators {
  double f1 = 0.0;        // [-] relative RMS error
  double f2 = 0.0;        // [-] 1 − Pearson correlation of mesh amplitudes, in [0, 2]
  double f3 = 0.0;        // [-] MAPE of mesh amplitudes (fraction)
  bool valid = false;     // false when an indicator is undefined (see compute_indicators)
  std::size_t tones = 0;  // [-] amplitudes compared by f2 and f3 (resolved in the measurement)
};

/// Fewest resolved tones f2 and f3 are computed from.
inline constexpr std::size_t kMinTones = 3;

/// Indicators of a simulated point against a measured one.
/// Undefined cases give valid = false and the offending indicator set to a
/// large penalty (kIndicatorPenalty) so that an optimizer moves away from it:
/// RMS_m ≤ 0, counts that differ, fewer than kMinTones resolved tones, or a
/// constant amplitude vector (Pearson ρ undefined).
Indicators compute_indicators(const dsp::PointFeatures& simulated,
                              const dsp::PointFeatures& measured);

inline constexpr double kIndicatorPenalty = 1e3;

/// True when f1, f2 and f3 are all at or below the paper's thresholds.
bool within_thresholds(const Indicators& i);

/// Largest of f1/0.5, f2/0.2, f3/0.2: ≤ 1 exactly when within_thresholds().
double worst_threshold_ratio(const Indicators& i);

}  // namespace model::calibration
