// The host tools a user runs (the recording synthesizers, the benchmarks) validate every
// numeric option with the same layer as drivetwin's commands (app/cli/options.hpp via
// tools/common/options.hpp). Each tool's options are declared in its <tool>_options.hpp,
// which its main() uses; here they are parsed in-process exactly as main() parses them.
// One table per tool, as in tests/app/cli/test_option_validation.cpp: each option gets the
// values no option may take (NaN, ±inf, an overflow, text, trailing text, an empty value)
// and the values out of its own range; each must be refused by the parser (so before
// anything is simulated or written: CLI11 runs the validators while parsing) with the
// option, the value and the expected range in the message, and a non-zero exit status.
// A valid value of the same option must pass. Before these validators `--drift nan`,
// `--fs inf` or `--steps 12abc` (read by atol as 12) were taken as given.
#include <gtest/gtest.h>

#include <CLI/CLI.hpp>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "accumulator_bench/accumulator_bench_options.hpp"
#include "calibration/calibration_bench_options.hpp"
#include "calibration/synth_calibration_bundle_options.hpp"
#include "common/options.hpp"
#include "diagnosis/synth_lumped_bundle_options.hpp"
#include "dynamics_bench/dynamics_bench_options.hpp"
#include "gearbox_generator/synth_independent_bundle_options.hpp"
#include "support/option_table.hpp"
#include "truth/truth_synth_options.hpp"

namespace {

using test_support::NumericOption;
using test_support::refused_values;

// paper-2mw's rated point (shared/reference/drivetrain-2mw.md: 14.8 rpm, 1.23e6 N·m) and
// the range a recording of it is held to (120 % of rated speed, 150 % of rated torque):
// 17.76 rpm and 1.845e6 N·m.
const tools::options::OperatingRange kPaperRange{1.2 * 14.8, 1.5 * 1.23e6};

/// What parsing one command line ended with.
struct Parsed {
  int exit_code = 0;
  std::string message;  // the parser's error ("" when it took the line)
};

using Declare = std::function<void(CLI::App&)>;

/// Parses `args` (without the program name) with a fresh app whose options `declare` adds,
/// as a tool's main() does (CLI11_PARSE: the exit status of the error it throws).
Parsed parse(const Declare& declare, const std::vector<std::string>& args) {
  CLI::App cli{"tool"};
  declare(cli);
  std::vector<const char*> argv{"tool"};
  for (const std::string& a : args) argv.push_back(a.c_str());
  try {
    cli.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::ParseError& e) {
    return {e.get_exit_code(), e.what()};
  }
  return {};
}

// Quoted, so that an empty or blank value shows.
std::string joined(const std::vector<std::string>& args) {
  std::string s = "tool";
  for (const auto& a : args) s += " '" + a + "'";
  return s;
}

void expect_validated(const Declare& declare, const std::vector<std::string>& base,
                      const std::vector<NumericOption>& options) {
  // The base line itself (defaults) passes.
  const Parsed defaults = parse(declare, base);
  EXPECT_EQ(defaults.exit_code, 0) << joined(base) << ": " << defaults.message;
  for (const NumericOption& o : options) {
    for (const std::string& value : refused_values(o)) {
      std::vector<std::string> args = base;
      args.insert(args.end(), {o.name, value});
      // Act
      const Parsed r = parse(declare, args);
      // Assert: refused naming the option, the value and what was expected.
      EXPECT_NE(r.exit_code, 0) << joined(args);
      EXPECT_NE(r.message.find(o.name + ": "), std::string::npos)
          << joined(args) << ": " << r.message;
      EXPECT_NE(r.message.find(value), std::string::npos) << joined(args) << ": " << r.message;
      EXPECT_NE(r.message.find("expected"), std::string::npos) << joined(args) << ": " << r.message;
    }
    for (const std::string& value : o.valid) {
      std::vector<std::string> args = base;
      args.insert(args.end(), {o.name, value});
      const Parsed r = parse(declare, args);
      EXPECT_EQ(r.exit_code, 0) << joined(args) << ": " << r.message;
    }
  }
}

// What every tool writing a recording of paper-2mw shares: its operating range, a
// vibration sample rate, a length, a seed.
const NumericOption kRpm{"--rpm", {"0", "-8.33", "17.8", "80"}, {"8.33", "17.7"}};
const NumericOption kTorque{"--torque", {"-1", "1.85e6", "5e7"}, {"0", "361747", "1.84e6"}};
const NumericOption kFs{"--fs", {"0", "100", "4095", "2e6"}, {"4096", "25600"}};
const NumericOption kSeed{"--seed", {"-1", "4294967296"}, {"0", "7"}, true};

TEST(ToolOptions, SynthCalibrationBundle) {
  tools::calibration::SynthCalibrationOptions o;
  const Declare declare = [&](CLI::App& cli) {
    tools::calibration::add_options(cli, o, kPaperRange);
  };
  expect_validated(declare, {"--out", "bundle"},
                   {kRpm,
                    kTorque,
                    kFs,
                    kSeed,
                    {"--damping-factor", {"0", "-2", "101"}, {"2", "0.5"}},
                    {"--mesh-scale", {"0", "-0.8"}, {"0.8"}},
                    {"--bearing-scale", {"0", "1000"}, {"1.3"}},
                    {"--noise", {"-0.05", "11"}, {"0", "0.05"}},
                    {"--duration", {"0", "-6", "3601"}, {"6", "0.5"}},
                    {"--settle", {"-0.5", "61"}, {"0", "0.5"}}});
  // A word option too: a model that does not exist.
  const Parsed r = parse(declare, {"--out", "bundle", "--model", "exact"});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.message.find("--model: 'exact' is not one of full, rom, lumped"), std::string::npos)
      << r.message;
}

TEST(ToolOptions, SynthLumpedBundle) {
  tools::diagnosis::SynthLumpedOptions o;
  const Declare declare = [&](CLI::App& cli) {
    tools::diagnosis::add_options(cli, o, kPaperRange);
  };
  expect_validated(declare, {"--out", "bundle"},
                   {kRpm,
                    kTorque,
                    kFs,
                    kSeed,
                    {"--severity", {"-0.3"}, {"0", "0.3", "1e-4"}},
                    {"--duration", {"0", "3601"}, {"30"}},
                    // A drift of 100 % would stop the rotor: below one.
                    {"--drift", {"-0.01", "1", "1.5"}, {"0", "0.02", "0.99"}},
                    {"--drift-period", {"0", "-23"}, {"23"}},
                    {"--noise", {"-1", "10.5"}, {"0.05"}},
                    {"--gain-error", {"-0.1", "1"}, {"0", "0.1"}},
                    {"--stiffness-scale", {"0", "-1"}, {"1", "0.9"}},
                    {"--damping-scale", {"0", "200"}, {"1"}},
                    {"--slip", {"-0.01", "1"}, {"0", "0.01"}},
                    {"--damping-ratio", {"0", "1", "-0.02"}, {"0.02"}}});
}

TEST(ToolOptions, SynthIndependentBundle) {
  tools::generator::SynthIndependentOptions o;
  const Declare declare = [&](CLI::App& cli) {
    tools::generator::add_options(cli, o, kPaperRange);
  };
  // CLI::PositiveNumber took "inf" before (+inf > 0).
  expect_validated(declare, {"--out", "bundle"},
                   {kRpm,
                    kTorque,
                    kFs,
                    kSeed,
                    {"--duration", {"0", "-30", "3601"}, {"30"}},
                    {"--settle", {"-1", "61"}, {"0", "1"}}});
}

TEST(ToolOptions, TruthSynthOne) {
  tools::truth_synth::OneCaseOptions one;
  tools::truth_synth::ListOptions list;
  const Declare declare = [&](CLI::App& cli) {
    tools::truth_synth::add_options(cli, one, list, kPaperRange);
  };
  expect_validated(declare, {"one", "--out", "cases"},
                   {kRpm,
                    kTorque,
                    kSeed,
                    {"--seconds", {"0", "-16", "3601"}, {"16"}},
                    {"--noise", {"-0.05", "11"}, {"0.05"}},
                    {"--drift", {"-0.02", "1"}, {"0.02"}},
                    {"--jitter", {"-0.01", "1"}, {"0.01"}},
                    {"--offset-spread", {"-1", "11"}, {"0", "1"}}});
  // Each of the two gains, and an effect parameter's value.
  for (const std::string gains : {"1.05,nan", "inf,0.94", "0,1", "1,-0.9"}) {
    const Parsed r = parse(declare, {"one", "--out", "cases", "--gain", gains});
    EXPECT_NE(r.exit_code, 0) << gains;
    EXPECT_NE(r.message.find("--gain: "), std::string::npos) << gains << ": " << r.message;
  }
  EXPECT_EQ(parse(declare, {"one", "--out", "cases", "--gain", "1.05,0.94"}).exit_code, 0);
  for (const std::string param : {"stiffness_loss=nan", "stiffness_loss=0.3x", "stiffness_loss",
                                  "=0.3", "stiffness_loss=inf"}) {
    const Parsed r = parse(declare, {"one", "--out", "cases", "--param", param});
    EXPECT_NE(r.exit_code, 0) << param;
    EXPECT_NE(r.message.find("--param: '" + param + "' is not name=value"), std::string::npos)
        << param << ": " << r.message;
  }
  EXPECT_EQ(parse(declare, {"one", "--out", "cases", "--param", "stiffness_loss=0.3"}).exit_code,
            0);
}

TEST(ToolOptions, TruthSynthList) {
  tools::truth_synth::OneCaseOptions one;
  tools::truth_synth::ListOptions list;
  const Declare declare = [&](CLI::App& cli) {
    tools::truth_synth::add_options(cli, one, list, kPaperRange);
  };
  const std::string cases = std::string(DRIVETWIN_SOURCE_DIR) + "/tools/truth/cases.toml";
  // 0 keeps each case's own length.
  expect_validated(declare, {"list", cases, "--out", "cases"},
                   {{"--seconds", {"-1", "3601"}, {"0", "2"}}});
}

TEST(ToolOptions, CalibrationBench) {
  tools::calibration::CalibrationBenchOptions o;
  const Declare declare = [&](CLI::App& cli) { tools::calibration::add_options(cli, o); };
  // pagmo2's NSGA-II takes a population that is a multiple of 4 (and at least 5).
  expect_validated(declare, {},
                   {{"--population", {"0", "4", "22", "-20", "1004"}, {"8", "20"}, true},
                    {"--iterations", {"0", "-9", "10001"}, {"1", "9"}, true},
                    {"--seeds", {"0", "1001"}, {"1", "10"}, true},
                    {"--revolutions", {"0", "7", "1025"}, {"8", "32"}, true},
                    {"--samples-per-rev", {"0", "128", "157", "4097"}, {"158", "256"}, true},
                    {"--tr-radius", {"0", "-0.5", "11"}, {"0.5"}},
                    {"--windows", {"0", "65", "-1"}, {"1", "4"}, true}});
  // --bundle: a recorded bundle's directory, refused when there is none.
  const Parsed missing = parse(declare, {"--bundle", "no-such-bundle-dir"});
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_NE(missing.message.find("no-such-bundle-dir"), std::string::npos) << missing.message;
  const Parsed r = parse(declare, {"--scenario", "hot"});
  EXPECT_NE(r.message.find("--scenario: 'hot' is not one of cold, warm-rated, warm-drift, all"),
            std::string::npos)
      << r.message;
}

TEST(ToolOptions, AccumulatorAndDynamicsBenches) {
  tools::bench::AccumulatorBenchOptions a;
  expect_validated([&](CLI::App& cli) { tools::bench::add_options(cli, a); }, {},
                   {{"--steps", {"0", "-1", "1000000001"}, {"1", "102400"}, true}});
  const Parsed only =
      parse([&](CLI::App& cli) { tools::bench::add_options(cli, a); }, {"--only", "full"});
  EXPECT_NE(only.message.find("--only: 'full' is not one of rom, former, accumulator"),
            std::string::npos)
      << only.message;
  tools::bench::DynamicsBenchOptions d;
  expect_validated([&](CLI::App& cli) { tools::bench::add_options(cli, d); }, {},
                   {{"--rom-steps", {"0", "-1"}, {"1", "256000"}, true},
                    {"--full-seconds", {"0", "-0.25", "61"}, {"0.25", "2"}}});
}

}  // namespace
