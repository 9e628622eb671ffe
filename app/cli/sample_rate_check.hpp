#pragma once
// What a ROM sample-rate option means for a particular turbine: the second half of the
// option validation layer (app/cli/options.hpp refuses what no turbine could take while
// parsing; this refuses what the loaded drivetrain cannot take). Used by `simulate
// --rate`, `damage --rom-rate` (dynamics spectra) and `damage-check --sample-rate`.
//
// Thread context: command code (start-up), allocates.

#include <string>

#include "model/drivetrain/description.hpp"

namespace app::cli {

/// Factors of the sample rate over the fastest line it must hold.
struct SampleRateNeeds {
  double mesh_factor = 2.56;  // [-] rate / highest mesh frequency (2.56: anti-aliased analyser)
  double mode_factor = 2.56;  // [-] rate / ROM mode cut-off
  const char* mesh_why = "2.56x: above Nyquist with an anti-alias margin";
};

/// "" when `rate_hz` can hold the highest mesh line of `drivetrain` at `max_rotor_rpm` and
/// the ROM's modes up to `cutoff_hz`; otherwise the refusal, naming `option` (and
/// `cutoff_option` when lowering the cut-off would also do), the lines and the least
/// rate that would do:
///   --rate: 100 Hz cannot represent this simulation: the high-speed mesh line at 372.4 Hz
///   (rotor 8.33 rpm) needs >= 2235 Hz (...) and the ROM's modes up to 2200 Hz need >=
///   5632 Hz (2.56x); expected >= 5632 Hz
std::string check_sample_rate(const char* option, double rate_hz,
                              const model::Drivetrain& drivetrain, double max_rotor_rpm,
                              double cutoff_hz, const char* cutoff_option,
                              const SampleRateNeeds& needs = {});

}  // namespace app::cli
