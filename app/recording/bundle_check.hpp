#pragma once
// The one validation layer for recording bundles (shared/reference/recording-bundle.md)
// that commands reading a recording use: `calibrate`, `diagnose`, `replay`. hal's
// read_bundle() enforces the format (files, fields, units: converted to SI or refused);
// what needs the drivetrain is checked here:
//
//   - the drivetrain: the bundle's `drivetrain` (a built-in name, or a path relative to
//     the bundle) or the caller's override, loaded and validated (app/config);
//   - the operating point inside the turbine's range (operating_range()): rotor speed
//     ≤ 120 % of rated, input torque ≤ 150 % of rated, wind ≤ 120 % of cut-out;
//   - every channel's `location` a component id of that drivetrain;
//   - metadata against the signal:
//       * a tacho (kind once_per_rev) on a shaft of the drivetrain: its mean pulse rate,
//         through the drivetrain's ratios, must give rotor_speed_rpm within
//         kSpeedTolerance (the contract allows ±2 % drift over a recording);
//       * the gear-mesh lines of the acceleration channels must stand out where
//         rotor_speed_rpm and sample_rate_hz put them: a sample rate declared wrong, or
//         a wrong speed, moves every line by the same factor (find_mesh_line_scale());
//         a recording in which no mesh line stands out anywhere convincingly is not
//         refused, it is reported unchecked (notes);
//       * a tacho and the mesh lines that disagree with the metadata are named together,
//         with what would reconcile them;
//   - the input torque: recorded, or — the contract's rule when only the wind speed is
//     given — estimated with the wind load model (model/wind) at the recorded wind and
//     rotor speed, and said so in notes.
//
// Every refusal is a BundleCheckError whose message names the file, the field and what
// was expected (and, for a mismatch, both values and what to look at).
//
// Thread context: start-up / command code (allocates, throws); never on the RT path.

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "hal/recording_bundle.hpp"
#include "model/drivetrain/description.hpp"

namespace app::recording {

/// Relative speed mismatch accepted between metadata and signal [-]: the contract's ±2 %
/// drift of a recording plus the resolution of a mean over it.
inline constexpr double kSpeedTolerance = 0.03;
/// A mesh line "stands out" when its peak is this many times the median amplitude of
/// the band around it (≈ 18 dB).
inline constexpr double kLineProminence = 8.0;
/// Turbine range factors (operating_range()).
inline constexpr double kOverspeedFactor = 1.2;    // [-] × rated rotor speed
inline constexpr double kPeakTorqueFactor = 1.5;   // [-] × rated torque
inline constexpr double kCutOutWindFactor = 1.2;   // [-] × cut-out wind (hysteresis, gusts)

class BundleCheckError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The turbine's range of a drivetrain description, for hal::read_bundle / write_bundle.
hal::OperatingRange operating_range(const model::Drivetrain& drivetrain);

struct BundleCheckOptions {
  std::string drivetrain;  // NAME|FILE overriding the bundle's drivetrain ("" = the bundle's)
};

struct CheckedBundle {
  hal::Recording recording;           // channels in SI units (hal::read_bundle)
  model::Drivetrain drivetrain;       // loaded and validated
  std::string drivetrain_source;      // the built-in name or the file it came from
  double input_torque_nm = 0.0;       // [N·m] recorded, or from the wind load model
  bool torque_estimated = false;      // true when from the wind (see notes)
  std::optional<double> tacho_rotor_rpm;  // [rpm] from the tacho, when there is one
  std::optional<double> mesh_line_scale;  // [-] measured/expected mesh line frequency
  /// Assumptions and conversions, one printable line each; commands print them.
  std::vector<std::string> notes;
};

/// Reads `dir` with hal::read_bundle and runs every check above.
/// @throws BundleCheckError naming the file, the field and what was expected
CheckedBundle load_bundle(const std::filesystem::path& dir, const BundleCheckOptions& options = {});

/// The checks that need the drivetrain, on a recording already read (for callers that
/// build one in memory). `bundle_dir` names the files in messages.
/// @throws BundleCheckError
void check_against_drivetrain(CheckedBundle& bundle, const std::filesystem::path& bundle_dir);

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
  double scale = 1.0;        // [-]
  std::size_t lines = 0;     // lines of the family (harmonics 1–3) that stand out
  double prominence = 0.0;   // [-] best line's peak / local median
  std::size_t checked = 0;   // stages resolvable in the spectrum (0: nothing to check)
  std::size_t hint_fundamentals = 0;  // stages whose fundamental stands out at hint_scale
};
/// `channels`: the acceleration channels; a line stands out when it does in any of them.
MeshLineScale find_mesh_line_scale(const std::vector<const std::vector<double>*>& channels,
                                   double sample_rate_hz, const std::vector<double>& expected_hz,
                                   double hint_scale = 0.0);

}  // namespace app::recording
