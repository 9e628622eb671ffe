#pragma once
// calibration_bench's command line (validated: tools/common/options.hpp).
#include <CLI/CLI.hpp>

#include <charconv>
#include <cstddef>
#include <string>

#include "common/options.hpp"

namespace tools::calibration {

struct CalibrationBenchOptions {
  std::size_t population = 20;
  std::size_t iterations = 9;
  std::size_t seeds = 10;
  std::size_t revolutions = 32;
  std::size_t samples_per_rev = 256;
  bool lumped = false;
  std::string scenario = "all";
  std::string only;
  std::string space = "paper";
  std::string bundle;       // a recorded bundle as the measurement
  std::size_t windows = 4;  // windows averaged from the bundle (calibrate's default)
  bool recording_rate = false;
  double tr_radius = 0.0;  // [-] set by the caller to TrustRegionConfig's default
};

/// NSGA-II (pagmo2) takes a population that is a multiple of 4, at least 8.
inline bool is_population(const std::string& text, std::string* error) {
  long long v = 0;
  const char* end = text.data() + text.size();
  const auto res = std::from_chars(text.data(), end, v);
  if (res.ec != std::errc() || res.ptr != end || v < 8 || v > 1000 || v % 4 != 0) {
    *error = "'" + text + "' is not a population; expected a multiple of 4 from 8 to 1000";
    return false;
  }
  return true;
}

inline void add_options(CLI::App& cli, CalibrationBenchOptions& o) {
  namespace opt = tools::options;
  cli.add_option("--population", o.population,
                 "Population of every population method (default 20; NSGA-II needs a multiple "
                 "of 4)")
      ->check(app::cli::accepted_by(is_population, "a multiple of 4 from 8 to 1000", "INT"));
  cli.add_option("--iterations", o.iterations,
                 "Iterations / generations (default 9: budget 20 x 10 = 200)")
      ->check(opt::integer_in(1, 10000, "iterations"));
  cli.add_option("--seeds", o.seeds, "Seeds per method (default 10)")
      ->check(opt::integer_in(1, 1000, "seeds"));
  cli.add_option("--scenario", o.scenario, "cold, warm-rated, warm-drift or all")
      ->check(opt::one_of({"cold", "warm-rated", "warm-drift", "all"}));
  // ≥ 8 revolutions: the closest compared tones (order 0.96 and DC) stay > 2 Hann main
  // lobes (4/R orders) apart; Nyquist order ≥ 79 > 3 × the hss mesh order (26).
  cli.add_option("--revolutions", o.revolutions, "hss revolutions per analysis block (default 32)")
      ->check(opt::integer_in(8, 1024, "revolutions"));
  cli.add_option("--samples-per-rev", o.samples_per_rev,
                 "Angle-domain samples per revolution (default 256)")
      ->check(opt::integer_in(158, 4096, "samples per revolution"));
  cli.add_flag("--lumped", o.lumped,
               "The lumped stand-in for truth and calibration (the old problem)");
  cli.add_option("--space", o.space,
                 "paper (default: the paper's 8 variables) or standard (calibrate's default "
                 "space: damping, stiffness, transmission error, housing modes)")
      ->check(opt::one_of({"paper", "standard"}));
  cli.add_option("--only", o.only,
                 "Run only the methods whose names contain one of these comma-separated texts "
                 "(e.g. 'trust', 'NSGA,MOEA')");
  cli.add_option("--bundle", o.bundle,
                 "A recorded bundle as the measurement (e.g. synth_independent_bundle's), measured "
                 "as drivetwin calibrate does (with this bench's analysis); calibrate's standard "
                 "space, ours = calibrate's calibration stopped at the budget; cold only; the "
                 "improved MOGOA only when --only names it")
      ->check(CLI::ExistingDirectory);
  cli.add_flag("--recording-rate", o.recording_rate,
               "With --bundle: the ROM at the recording's rate, as calibrate runs it (default: 6 "
               "x the highest compared harmonic)");
  cli.add_option("--windows", o.windows, "With --bundle: windows averaged (default 4)")
      ->check(opt::integer_in(1, 64, "windows"));
  cli.add_option("--tr-radius", o.tr_radius,
                 "Trust region: initial radius (default: TrustRegionConfig's)")
      ->check(opt::number_in(0.0, 10.0, "", true));
}

}  // namespace tools::calibration
