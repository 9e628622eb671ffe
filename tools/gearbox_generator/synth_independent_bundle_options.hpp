#pragma once
// synth_independent_bundle's command line (validated: tools/common/options.hpp). The
// turbine's range bounds --rpm and --torque only: the generator itself stays independent
// of the twin's model code.
#include <CLI/CLI.hpp>

#include <cstdint>
#include <string>

#include "common/options.hpp"
#include "independent_gearbox.hpp"

namespace tools::generator {

struct SynthIndependentOptions {
  std::string out;
  GeneratorSettings settings;
  std::uint64_t seed = 1;
  bool no_tacho = false;
};

inline void add_options(CLI::App& cli, SynthIndependentOptions& o,
                        const tools::options::OperatingRange& range) {
  namespace opt = tools::options;
  GeneratorSettings& s = o.settings;
  cli.add_option("--out", o.out, "Bundle directory to write")->required();
  cli.add_option("--rpm", s.rotor_speed_rpm, "Mean rotor speed [rpm]")
      ->check(opt::rotor_speed(range));
  cli.add_option("--torque", s.input_torque_nm, "Mean rotor torque [N·m]")
      ->check(opt::rotor_torque(range));
  cli.add_option("--duration", s.duration_s, "Length [s]")->check(opt::recording_length());
  cli.add_option("--seed", o.seed,
                 "Seed of the generator's choices (structure, excitation, sensors)")
      ->check(opt::seed());
  cli.add_option("--fs", s.sample_rate_hz, "Sample rate [Hz]")->check(opt::vibration_rate());
  cli.add_option("--settle", s.settle_s, "Seconds simulated and discarded first")
      ->check(opt::number_in(0.0, 60.0, "s"));
  cli.add_flag("--no-tacho", o.no_tacho, "Leave out the once-per-revolution hss tacho");
}

}  // namespace tools::generator
