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
#include "recording/mesh_lines.hpp"

namespace app::recording {

/// Turbine range factors (operating_range()).
inline constexpr double kOverspeedFactor = 1.2;   // [-] × rated rotor speed
inline constexpr double kPeakTorqueFactor = 1.5;  // [-] × rated torque
inline constexpr double kCutOutWindFactor = 1.2;  // [-] × cut-out wind (hysteresis, gusts)

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
  hal::Recording recording;               // channels in SI units (hal::read_bundle)
  model::Drivetrain drivetrain;           // loaded and validated
  std::string drivetrain_source;          // the built-in name or the file it came from
  double input_torque_nm = 0.0;           // [N·m] recorded, or from the wind load model
  bool torque_estimated = false;          // true when from the wind (see notes)
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

}  // namespace app::recording
