#pragma once
// Where the gear-mesh lines of vibration channels sit relative to where a rotor speed
// and the drivetrain's tooth counts put them: the signal-side speed check shared by the
// bundle validation layer (bundle_check.hpp: metadata against the recording) and
// `bus probe` (the CMS stream against the other speed sources).
//
// Thread context: start-up / command code (allocates the FFT); not the RT path.

#include <cstddef>
#include <vector>

namespace app::recording {

/// Relative speed mismatch accepted between metadata and signal [-]: the contract's ±2 %
/// drift of a recording plus the resolution of a mean over it.
inline constexpr double kSpeedTolerance = 0.03;
/// Recordings shorter than this are not checked [samples].
inline constexpr std::size_t kMinMeshSamples = 4096;
/// A mesh line "stands out" when its peak is this many times the median amplitude of
/// the band around it (≈ 18 dB).
inline constexpr double kLineProminence = 8.0;
/// How far the gear-mesh lines of the channels sit from `expected_hz` (one mesh frequency
/// per stage), from the amplitude spectra of their last ≤ 65 536 samples. A line "stands
/// out" when it is the strongest of the band 0.8–1.25 × its frequency and kLineProminence
/// × the band's median, in any channel. The scale s is
///   1 (the metadata) when a stage's mesh fundamental stands out there; else
///   `hint_scale` (the tacho's, when > 0) when one stands out there; else
///   the scale in [0.2, 5] at which the most fundamentals stand out (then the most lines
///   of harmonics 1–3), when that family is convincing (two fundamentals, or one with two
///   harmonics); lines = 0 (unchecked) when nothing is convincing. That scale may be a
///   multiple of the true one (a family's lines are also harmonics of lower families).
/// Conservative by design: a good recording is never moved off s = 1 while its mesh line
/// is there; the price is that a sample rate declared m times too low, which puts the
/// true m-th harmonics where the fundamentals belong, is not seen here (the tacho sees it).
/// Refined on the strongest fundamental.
struct MeshLineScale {
  double scale = 1.0;                 // [-]
  std::size_t lines = 0;              // lines of the family (harmonics 1–3) that stand out
  double prominence = 0.0;            // [-] best line's peak / local median
  std::size_t checked = 0;            // stages resolvable in the spectrum (0: nothing to check)
  std::size_t hint_fundamentals = 0;  // stages whose fundamental stands out at hint_scale
};
/// `channels`: the acceleration channels; a line stands out when it does in any of them.
MeshLineScale find_mesh_line_scale(const std::vector<const std::vector<double>*>& channels,
                                   double sample_rate_hz, const std::vector<double>& expected_hz,
                                   double hint_scale = 0.0);

}  // namespace app::recording
