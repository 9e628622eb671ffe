#pragma once
// The drivetrain description file (TOML, format `drivetwin-drivetrain/1`):
// every field of model::Drivetrain, documented with a full example in
// app/config/README.md. A file may start from a built-in description
// (`base = "paper-2mw"`) and override keys; list entries ([[gears]], ...) are
// matched by `id` (measurement points by `channel`): a known id overrides the
// keys it names, a new id appends an entry.
//
// `--drivetrain NAME|FILE` convention: a built-in name (paper-2mw,
// kelmarsh-mm92) or a path to such a file; add_drivetrain_option() registers it
// on a subcommand with paper-2mw as default.
//
// Errors: DrivetrainFileError, whose message names the file, the line, the full
// dotted key (e.g. `gears[2].teeth`) and what was expected.
//
// Thread context: start-up only (allocates, throws); never on the RT path.

#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "model/drivetrain/description.hpp"

namespace CLI {  // NOLINT(readability-identifier-naming): CLI11's own namespace
class App;
class Option;
}  // namespace CLI

namespace app::config {

inline constexpr const char* kDrivetrainFormat = "drivetwin-drivetrain/1";
inline constexpr const char* kDefaultDrivetrain = "paper-2mw";

class DrivetrainFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Built-in descriptions: model's (paper-2mw) and the files embedded from app/data/.
std::vector<std::string> builtin_drivetrain_names();

/// A built-in name or a path to a TOML description file.
model::Drivetrain load_drivetrain(const std::string& name_or_path);

/// Parses TOML text; `source` names it in error messages (a path or "<builtin x>").
/// Relative `base` names are built-ins only.
model::Drivetrain parse_drivetrain(std::string_view toml_text, const std::string& source);

/// Writes every field as a complete, self-contained TOML description (no `base`).
std::string to_toml(const model::Drivetrain& drivetrain);

/// The [dynamics] table alone (every key of model::DynamicsParameters, shortest round-trip
/// decimal): what a calibration changes, in the description's own format.
std::string dynamics_to_toml(const model::DynamicsParameters& parameters);

/// Reads a document holding only a [dynamics] table over `base` (a key it does not give keeps
/// base's value), with the description's names and ranges. Throws DrivetrainFileError naming
/// source, line, column and key.
model::DynamicsParameters parse_dynamics(std::string_view toml_text, const std::string& source,
                                         const model::DynamicsParameters& base);

/// Adds `--drivetrain NAME|FILE` (default paper-2mw) to a subcommand. Defined with
/// the command-line plumbing (app/cli/command.cpp): only subcommands see CLI11.
CLI::Option* add_drivetrain_option(CLI::App& sub, std::string& value);

}  // namespace app::config
