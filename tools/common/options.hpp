#pragma once
// The host tools' command options go through the one validation layer every drivetwin
// command uses (app/cli/options.hpp, header-only over CLI11): a bad value is refused while
// the command line is parsed, before anything is simulated or written, naming the option,
// the value and what was expected:
//
//   synth_lumped_bundle: --drift: 1.5 is out of range; expected a number in [0, 1)
//
// Each tool declares its options in a header of its own (<tool>_options.hpp: a struct of
// the values and `add_options(CLI::App&, ...)`), which its main() and the tests
// (tests/tools/test_tool_options.cpp) share. Below: what several tools need.
//
// Thread context: command-line parsing (start-up only).

#include <cstdint>
#include <limits>

#include "cli/options.hpp"
#include "model/drivetrain/description.hpp"
#include "recording/bundle_check.hpp"  // the turbine's range a recording is held to

namespace tools::options {

using app::cli::integer_in;
using app::cli::kInf;
using app::cli::non_negative;
using app::cli::number_in;
using app::cli::number_in_or;
using app::cli::one_of;
using app::cli::positive;

/// The operating range a synthesized recording must stay inside: the one `calibrate`
/// and `diagnose` hold a recording of this turbine to (app/recording/bundle_check.hpp),
/// so a tool never writes a bundle the twin then refuses.
struct OperatingRange {
  double max_rotor_rpm = 0.0;  // [rpm] 120 % of rated
  double max_torque_nm = 0.0;  // [N·m] 150 % of rated
};

inline OperatingRange operating_range(const model::Drivetrain& d) {
  return {app::recording::kOverspeedFactor * d.turbine.rated_rotor_speed_rpm,
          app::recording::kPeakTorqueFactor * d.turbine.rated_torque_nm};
}

/// A rotor speed: > 0 and within the turbine's range.
inline CLI::Validator rotor_speed(const OperatingRange& r) {
  return number_in(0.0, r.max_rotor_rpm, "rpm", true);
}
/// A rotor (gearbox input) torque: ≥ 0 and within the turbine's range.
inline CLI::Validator rotor_torque(const OperatingRange& r) {
  return number_in(0.0, r.max_torque_nm, "N·m");
}
/// A vibration sample rate: from 4096 Hz (2.56 × the high-speed mesh line's ~790 Hz at
/// overspeed with its first harmonic, the least a mesh feature needs) to 1 MHz.
inline CLI::Validator vibration_rate() { return number_in(4096.0, 1e6, "Hz"); }
/// A recorded length: > 0, at most an hour (a synthesized hour at 25.6 kHz is ~1.5 GB).
inline CLI::Validator recording_length() { return number_in(0.0, 3600.0, "s", true); }
/// A fraction that must stay below one (a speed drift, a gain error, a jitter, a slip).
inline CLI::Validator fraction_below_one() { return number_in(0.0, 1.0, "", false, true); }
/// Noise RMS relative to the signal's RMS: 0 (none) to 10.
inline CLI::Validator noise_ratio() { return number_in(0.0, 10.0); }
/// A multiplier of a physical parameter (stiffness, damping): > 0, at most 100.
inline CLI::Validator scale_factor() { return number_in(0.0, 100.0, "", true); }
/// A random seed.
inline CLI::Validator seed() {
  return integer_in(0, std::numeric_limits<std::uint32_t>::max(), "seed");
}

}  // namespace tools::options
