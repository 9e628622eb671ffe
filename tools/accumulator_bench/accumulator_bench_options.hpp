#pragma once
// accumulator_bench's command line (validated: tools/common/options.hpp).
#include <CLI/CLI.hpp>

#include <string>

#include "common/options.hpp"

namespace tools::bench {

struct AccumulatorBenchOptions {
  long steps = 4 * 25600;  // model steps (4 s at 25.6 kHz)
  std::string only;        // "": all three
};

inline void add_options(CLI::App& cli, AccumulatorBenchOptions& o) {
  namespace opt = tools::options;
  cli.add_option("--steps", o.steps, "Model steps per measurement (default 4 s at 25.6 kHz)")
      ->check(opt::integer_in(1, 1'000'000'000, "steps"));
  cli.add_option("--only", o.only, "Measure one: rom, former or accumulator")
      ->check(opt::one_of({"rom", "former", "accumulator"}));
}

}  // namespace tools::bench
