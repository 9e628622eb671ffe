#pragma once
// dynamics_bench's command line (validated: tools/common/options.hpp).
#include <CLI/CLI.hpp>

#include "common/options.hpp"

namespace tools::bench {

struct DynamicsBenchOptions {
  long rom_steps = 10 * 25600;  // ROM steps (10 s at 25.6 kHz)
  double full_seconds = 0.25;   // [s] simulated by the full model
  bool rom_only = false;
};

inline void add_options(CLI::App& cli, DynamicsBenchOptions& o) {
  namespace opt = tools::options;
  cli.add_option("--rom-steps", o.rom_steps, "ROM steps (default 10 s at 25.6 kHz)")
      ->check(opt::integer_in(1, 1'000'000'000, "steps"));
  cli.add_option("--full-seconds", o.full_seconds, "Simulated seconds of the full model [s]")
      ->check(opt::number_in(0.0, 60.0, "s", true));
  cli.add_flag("--rom-only", o.rom_only, "Measure the ROM only");
}

}  // namespace tools::bench
