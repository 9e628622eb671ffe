// Every numeric option of every command is validated while the command line is parsed
// (app/cli/options.hpp), and what needs the turbine once the drivetrain is loaded
// (app/cli/sample_rate_check.hpp). One table per command: each option gets the values no
// option may take (NaN, ±inf, an overflow, text, trailing text, an empty value) and the
// values out of its own range; each must exit non-zero with the option, the value and the
// expected range in the message, and write nothing. A valid value of the same option must
// pass the parser: the command then stops at its first input, which the base command line
// makes missing (so no test here runs a model), and the error names that input and not
// the option.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "support/option_table.hpp"
#include "support/run_command.hpp"

namespace {

namespace fs = std::filesystem;
using test_support::CommandResult;
using test_support::joined;
using test_support::NumericOption;
using test_support::refused_values;
using test_support::run_command;

class OptionValidation : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("drivetwin_options_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  // `base` stops at its first input, named `missing_input` in its error; `written` is what
  // the command would write (nothing may appear there).
  void expect_validated(const std::vector<std::string>& base, const std::string& missing_input,
                        const std::vector<NumericOption>& options) const {
    for (const NumericOption& o : options) {
      for (const std::string& value : refused_values(o)) {
        std::vector<std::string> args = base;
        args.insert(args.end(), {o.name, value});
        // Act
        const CommandResult r = run_command(args);
        // Assert: refused naming the option, the value and what was expected.
        EXPECT_NE(r.exit_code, 0) << joined(args);
        EXPECT_NE(r.error.find(o.name + ": "), std::string::npos) << joined(args) << "\n" << r;
        EXPECT_NE(r.error.find(value), std::string::npos) << joined(args) << "\n" << r;
        EXPECT_NE(r.error.find("expected"), std::string::npos) << joined(args) << "\n" << r;
        EXPECT_TRUE(fs::is_empty(dir_)) << joined(args) << " wrote into " << dir_;
      }
      for (const std::string& value : o.valid) {
        std::vector<std::string> args = base;
        args.insert(args.end(), {o.name, value});
        const CommandResult r = run_command(args);
        // Past the parser, the command stops at the missing input, not at the option.
        EXPECT_EQ(r.error.find(o.name + ":"), std::string::npos) << joined(args) << "\n" << r;
        EXPECT_NE(r.error.find(missing_input), std::string::npos) << joined(args) << "\n" << r;
        EXPECT_TRUE(fs::is_empty(dir_)) << joined(args) << " wrote into " << dir_;
      }
    }
  }

  fs::path dir_;
};

TEST_F(OptionValidation, Damage) {
  const std::string missing = path("missing.csv");
  expect_validated({"damage", missing, "--cache-dir", path("cache"), "--json", path("d.json")},
                   "missing.csv",
                   {{"--period", {"-600", "0", "31622401"}, {"600", "1"}},
                    {"--k-a", {"0.99", "0", "11"}, {"1", "1.25"}},
                    {"--k-h-beta", {"0.5", "-1", "11"}, {"0", "1", "1.15"}},
                    {"--f-ma", {"-0.1", "1.01"}, {"0", "0.5", "1"}},
                    {"--pinion-offset", {"-0.1", "0.5"}, {"0", "0.1"}},
                    {"--grade", {"0", "99", "-1"}, {"6"}, true},
                    {"--oil-viscosity-40", {"0", "0.5", "10000"}, {"320"}},
                    {"--oil-viscosity-100", {"0", "10000"}, {"35"}},
                    {"--oil-temperature", {"-41", "151"}, {"60", "-40"}},
                    {"--contamination", {"-0.1", "1.1"}, {"0.5"}},
                    {"--rom-rate", {"100", "255", "2e6"}, {"8192"}},
                    {"--rom-cutoff", {"5", "2501"}, {"2200"}}});
}

TEST_F(OptionValidation, DamageRefusesAnAliasingRomRateForThisTurbineBeforeReading) {
  // paper-2mw: the high-speed mesh line at 1.2 × rated (18.2 rpm) is ~793 Hz, the ROM's
  // default cut-off 2200 Hz: 1000 Hz holds neither (2.56 × 2200 = 5632 Hz).
  const CommandResult r =
      run_command({"damage", path("missing.csv"), "--spectrum", "dynamics", "--rom-rate", "1000",
                   "--cache-dir", path("cache"), "--json", path("d.json")});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.error.find("--rom-rate: 1000 Hz cannot represent this simulation"), std::string::npos)
      << r;
  EXPECT_NE(r.error.find("expected >= 5632 Hz"), std::string::npos) << r;
  EXPECT_TRUE(fs::is_empty(dir_));
}

TEST_F(OptionValidation, DamageSaysAMissingFileBeforeBuildingAndCachingTheSpectrum) {
  // Before: the load spectrum was built (minutes for a dynamics one) and cached before the
  // SCADA file was opened. The quasi-static spectrum shows it in an instant: no cache file.
  const CommandResult r =
      run_command({"damage", path("missing.csv"), "--cache-dir", path("cache")});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.error.find("missing.csv"), std::string::npos) << r;
  EXPECT_FALSE(fs::exists(path("cache"))) << "the spectrum was built before the file was read";
}

TEST_F(OptionValidation, DamageCheck) {
  expect_validated({"damage-check", path("missing.csv")}, "missing.csv",
                   {{"--rows", {"0", "-1", "100001"}, {"1", "6"}, true},
                    {"--period", {"0", "-600", "86401"}, {"600"}},
                    {"--sample-rate", {"0", "255", "2e6"}, {"4096", "8192"}},
                    {"--cutoff", {"0", "9", "2501"}, {"1500", "100"}}});
}

TEST_F(OptionValidation, DamageCheckRefusesARateTheMeshLinesOrTheCutOffNeed) {
  // 1000 Hz: below 2.56 × the high-speed mesh line at overspeed (~793 Hz) and 2.56 × the
  // default 1500 Hz cut-off (3840 Hz). 4096 Hz with a 2000 Hz cut-off: below 5120 Hz.
  const CommandResult slow =
      run_command({"damage-check", path("missing.csv"), "--sample-rate", "1000"});
  EXPECT_EQ(slow.exit_code, 1);
  EXPECT_NE(slow.error.find("--sample-rate: 1000 Hz cannot represent"), std::string::npos) << slow;
  EXPECT_NE(slow.error.find("expected >= 3840 Hz"), std::string::npos) << slow;
  const CommandResult cutoff =
      run_command({"damage-check", path("missing.csv"), "--cutoff", "2000"});
  EXPECT_EQ(cutoff.exit_code, 1);
  EXPECT_NE(cutoff.error.find("modes up to 2000 Hz (--cutoff) need >= 5120 Hz"), std::string::npos)
      << cutoff;
  EXPECT_TRUE(fs::is_empty(dir_));
}

TEST_F(OptionValidation, Simulate) {
  const std::string toml = path("missing.toml");
  const std::string out = path("sim");
  const std::vector<NumericOption> common{{"--seconds", {"0", "-1", "3601"}, {"1"}},
                                          {"--rate", {"0", "-25600"}, {"25600"}},
                                          {"--run-in", {"-1", "601"}, {"0", "1"}},
                                          {"--loads-every", {"0", "-1", "1000001"}, {"10"}, true}};
  expect_validated({"simulate", "--torque", "1000", "--out", out, "--drivetrain", toml},
                   "missing.toml", {{"--rpm", {"0", "-5"}, {"8.33"}}});
  expect_validated({"simulate", "--rpm", "8.33", "--out", out, "--drivetrain", toml},
                   "missing.toml", {{"--torque", {"-1"}, {"0", "361747"}}});
  expect_validated(
      {"simulate", "--rpm", "8.33", "--torque", "1000", "--out", out, "--drivetrain", toml},
      "missing.toml", common);
}

TEST_F(OptionValidation, SynthScadaSteady) {
  expect_validated({"synth-scada", "--out", path("s.csv"), "--drivetrain", path("missing.toml")},
                   "missing.toml",
                   {{"--years", {"0", "-1", "101"}, {"1"}},
                    {"--days", {"0", "-1", "36526"}, {"1"}},
                    {"--period", {"0", "86401"}, {"600"}},
                    {"--weibull-k", {"0", "-2"}, {"2"}},
                    {"--weibull-c", {"0", "-8"}, {"8"}},
                    {"--lag1", {"0", "1", "-0.5"}, {"0.9"}},
                    {"--slow-weight", {"0", "1.1"}, {"0.5", "1"}},
                    {"--slow-time-constant", {"0", "-1"}, {"86400"}},
                    {"--fast-lag1", {"1", "-0.1"}, {"0", "0.5"}},
                    {"--seasonal-amplitude", {"1", "-0.1"}, {"0", "0.2"}},
                    {"--seasonal-peak-day", {"-1", "366"}, {"30"}},
                    {"--diurnal-amplitude", {"1", "-0.1"}, {"0.1"}},
                    {"--diurnal-peak-hour", {"24", "-1"}, {"15"}},
                    {"--seed", {"-1"}, {"7"}, true},
                    {"--start", {}, {"0", "1420070400"}}});
}

TEST_F(OptionValidation, SynthScadaTurbulent) {
  const std::vector<std::string> base{"synth-scada",
                                      "--out",
                                      path("s.csv"),
                                      "--drivetrain",
                                      path("missing.toml"),
                                      "--turbulence",
                                      "A",
                                      "--days",
                                      "1"};
  expect_validated(base, "missing.toml", {{"--mean-wind", {"-3", "70"}, {"6.75", "0"}}});
  std::vector<std::string> with_mean = base;
  with_mean.insert(with_mean.end(), {"--mean-wind", "6.75"});
  expect_validated(with_mean, "missing.toml",
                   {{"--resolution", {"0", "601"}, {"1", "600"}},
                    {"--hub-height", {"0", "-5", "501"}, {"80"}},
                    {"--rotor-inertia", {"0", "-1"}, {"3.5e7"}},
                    {"--step", {"0", "601"}, {"0.025"}},
                    {"--wind-sample", {"0", "601"}, {"0.25"}}});
}

TEST_F(OptionValidation, Diagnose) {
  expect_validated({"diagnose", path("missing-bundle")}, "missing-bundle",
                   {{"--evaluations", {"0", "-1", "100001"}, {"40"}, true},
                    {"--candidates", {"0", "21"}, {"3"}, true},
                    {"--fit-evaluations", {"0", "10001"}, {"10"}, true}});
}

TEST_F(OptionValidation, Calibrate) {
  // Its options got their validators when calib rewrote the command; their table here.
  expect_validated({"calibrate", path("missing-bundle"), "--json", path("c.json")},
                   "missing-bundle",
                   {{"--evaluations", {"-1", "100001"}, {"0", "10"}, true},
                    {"--population", {"0", "1", "65"}, {"2", "20"}, true},
                    {"--iterations", {"0", "100001"}, {"50"}, true},
                    {"--seed", {"-1"}, {"0", "1"}, true},
                    {"--revolutions", {"0", "7", "4097"}, {"8", "64"}, true},
                    {"--windows", {"0", "65"}, {"1", "4"}, true},
                    {"--samples-per-rev", {"0", "15", "65537"}, {"16", "1024"}, true},
                    {"--harmonics", {"0", "11"}, {"1", "3"}, true},
                    {"--residual-sd", {"-0.1", "11"}, {"0", "0.25"}}});
  const CommandResult r = run_command({"calibrate", path("missing-bundle"), "--method", "newton"});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.error.find("--method: 'newton' is not one of trust-region, improved, published"),
            std::string::npos)
      << r;
}

TEST_F(OptionValidation, Run) {
  // --duration was checked by CLI::Range, which lets NaN through (every comparison false).
  expect_validated({"run", "--config", path("missing.toml")}, "missing.toml",
                   {{"--duration", {"-1", "1e10"}, {"0", "60"}},
                    {"--speed", {"0", "-1", "2e6", "fast", "maxx"}, {"1", "2.5", "max"}}});
}

TEST_F(OptionValidation, BusProbe) {
  expect_validated(
      {"bus", "probe", "--config", path("missing.toml")}, "missing.toml",
      {{"--seconds", {"0", "0.001", "-1", "2e6"}, {"1"}}, {"--every", {"0", "3601"}, {"1"}}});
}

TEST_F(OptionValidation, MonthListsAndTimesNameTheOptionAndTheBadValueBeforeReading) {
  // Month lists and UTC times carry numbers too; `fit-cp --test-months` used to be read only
  // after the SCADA file (a missing file was said instead).
  struct Case {
    std::string command, option;
    std::vector<std::string> bad;
    std::string valid;
  };
  const std::vector<std::string> months{"13", "0", "1-x", "nan", "3-1", "1,,2", ""};
  const std::vector<std::string> times{"2019-13-01", "nan", "inf", "yesterday", "2019-01-01x", ""};
  for (const Case& c : std::vector<Case>{{"torque", "--months", months, "1-3"},
                                         {"torque", "--from", times, "2019-01-01"},
                                         {"torque", "--to", times, "1546300800"},
                                         {"fit-cp", "--fit-months", months, "DJF,MAM"},
                                         {"fit-cp", "--test-months", months, "4-12"},
                                         {"fit-cp", "--from", times, "2019-01-01 06:00:00"},
                                         {"fit-cp", "--to", times, "2019-07-01"},
                                         {"fit-cp", "--test-from", times, "2019-07-01"},
                                         {"fit-cp", "--test-to", times, "2020-01-01"}}) {
    for (const std::string& value : c.bad) {
      const std::vector<std::string> args{c.command, path("missing.csv"), c.option, value};
      const CommandResult r = run_command(args);
      EXPECT_NE(r.exit_code, 0) << joined(args);
      EXPECT_NE(r.error.find(c.option + ": "), std::string::npos) << joined(args) << "\n" << r;
      // The item at fault: the value, or its empty item ("1,,2", "").
      const std::string item = value.find(",,") != std::string::npos ? "" : value;
      EXPECT_TRUE(r.error.find("'" + item + "'") != std::string::npos ||
                  (item.empty() && r.error.find("no month given") != std::string::npos))
          << joined(args) << "\n"
          << r;
    }
    const std::vector<std::string> ok{c.command, path("missing.csv"), c.option, c.valid};
    const CommandResult r = run_command(ok);
    EXPECT_EQ(r.error.find(c.option + ":"), std::string::npos) << joined(ok) << "\n" << r;
    EXPECT_NE(r.error.find("missing.csv"), std::string::npos) << joined(ok) << "\n" << r;
  }
  EXPECT_TRUE(fs::is_empty(dir_));
}

}  // namespace
