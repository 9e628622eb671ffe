#pragma once
// truth_synth's command line (validated: tools/common/options.hpp). An effect's own
// parameters (`--param name=value`) must be finite numbers here; their ranges are the
// effect's (model/drivetrain/effects.hpp), checked once the effect is known.
#include <CLI/CLI.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "common/options.hpp"

namespace tools::truth_synth {

struct OneCaseOptions {
  std::string out, id = "case", effect, location;
  std::vector<std::string> params;  // name=value
  bool conceal = false, no_tacho = false;
  double rpm = 8.33;         // [rpm]
  double torque = 361747.0;  // [N·m]
  double seconds = 16.0;     // [s]
  double noise = 0.05;       // [-]
  double drift = 0.02;       // [-]
  std::vector<double> gain;  // [-] point1, point2
  double jitter = 0.01;      // [-]
  std::uint64_t seed = 1;
  double offset_spread = 1.0;  // [-]
};

struct ListOptions {
  std::string file, out, only;
  double seconds = 0.0;  // [s] 0: each case's own length
};

/// "name=value" with a finite number after the '='.
inline bool is_effect_parameter(const std::string& text, std::string* error) {
  const auto eq = text.find('=');
  double v = 0.0;
  if (eq == std::string::npos || eq == 0 ||
      !app::cli::detail::parse_finite(text.substr(eq + 1), v)) {
    *error = "'" + text + "' is not name=value; expected a name, '=' and a finite number";
    return false;
  }
  return true;
}

/// The `one` and `list` subcommands, with their options.
inline void add_options(CLI::App& cli, OneCaseOptions& one_o, ListOptions& list_o,
                        const tools::options::OperatingRange& range) {
  namespace opt = tools::options;
  cli.require_subcommand(1);
  CLI::App* one = cli.add_subcommand("one", "One case from the command line");
  one->add_option("--out", one_o.out, "Output directory")->required();
  one->add_option("--id", one_o.id, "Case id (bundle directory name)");
  one->add_option("--effect", one_o.effect,
                  "Effect id of the diagnosis contract (none: a control)");
  one->add_option("--location", one_o.location, "Component id of the effect");
  one->add_option("--param", one_o.params, "name=value of the effect's parameters")
      ->check(app::cli::accepted_by(is_effect_parameter, "name=value (a finite number)"));
  one->add_flag("--conceal", one_o.conceal, "Scale the severity until the effect is concealed");
  one->add_option("--rpm", one_o.rpm, "Nominal rotor speed [rpm]")->check(opt::rotor_speed(range));
  one->add_option("--torque", one_o.torque, "Input torque [N·m]")->check(opt::rotor_torque(range));
  one->add_option("--seconds", one_o.seconds, "Recorded length [s]")
      ->check(opt::recording_length());
  one->add_option("--noise", one_o.noise, "Noise RMS / healthy channel RMS")
      ->check(opt::noise_ratio());
  one->add_option("--drift", one_o.drift, "Slow speed drift amplitude (fraction)")
      ->check(opt::fraction_below_one());
  one->add_option("--gain", one_o.gain, "Sensor gains point1,point2")
      ->delimiter(',')
      ->expected(2)
      ->check(opt::number_in(0.0, 10.0, "", true));
  one->add_flag("--no-tacho", one_o.no_tacho, "No tacho channel");
  one->add_option("--jitter", one_o.jitter, "Bearing impact spacing jitter (fraction)")
      ->check(opt::fraction_below_one());
  one->add_option("--seed", one_o.seed, "Seed of noise, offsets and jitter")->check(opt::seed());
  one->add_option("--offset-spread", one_o.offset_spread, "× the default parameter offsets")
      ->check(opt::number_in(0.0, 10.0));

  CLI::App* list = cli.add_subcommand("list", "Every case of a case list (TOML)");
  list->add_option("file", list_o.file, "Case list")->required()->check(CLI::ExistingFile);
  list->add_option("--out", list_o.out, "Output directory")->required();
  list->add_option("--only", list_o.only, "Comma-separated case ids to run");
  list->add_option("--seconds", list_o.seconds, "Override every case's length [s]")
      ->check(opt::number_in_or(0.0, "each case's own length", 0.0, 3600.0, "s"));
}

}  // namespace tools::truth_synth
