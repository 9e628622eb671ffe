// `drivetwin torque` end to end, in-process (so it also runs under qemu-aarch64):
// bad SCADA files and bad descriptions in a temp dir give one message naming the
// file, row and column (or key) and a non-zero exit; a good file gives the MAPE
// of a hand calculation.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <CLI/CLI.hpp>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli/command.hpp"

namespace {

struct CliResult {
  int exit_code = 0;
  std::string error;  // what main() would print after "drivetwin: error: "
  std::string out;
};

// Mirrors app/main.cpp: parse, run the command's callback, map errors to exit codes.
CliResult run_cli(std::vector<std::string> args) {
  CLI::App cli{"drivetwin"};
  cli.require_subcommand(1);
  for (const auto& command : app::cli::commands()) {
    command.setup(*cli.add_subcommand(command.name, command.description));
  }
  std::vector<const char*> argv{"drivetwin"};
  for (const auto& a : args) argv.push_back(a.c_str());
  CliResult result;
  app::cli::exit_status() = 0;
  testing::internal::CaptureStdout();
  try {
    cli.parse(static_cast<int>(argv.size()), const_cast<char**>(argv.data()));
    result.exit_code = app::cli::exit_status();
  } catch (const CLI::ParseError& e) {
    result.exit_code = e.get_exit_code();
    result.error = e.what();
  } catch (const std::exception& e) {
    result.exit_code = 1;
    result.error = e.what();
  }
  result.out = testing::internal::GetCapturedStdout();
  return result;
}

class TorqueCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           (std::string("drivetwin_torque_") +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    const auto path = dir_ / name;
    std::ofstream(path, std::ios::binary) << text;
    return path.string();
  }
  std::filesystem::path dir_;
};

using ::testing::HasSubstr;

TEST_F(TorqueCli, MissingWindColumnIsAnErrorNamingFileAndColumn) {
  const std::string f = write("scada.csv", "t_s,rotor_speed_rpm\n0,8.33\n");
  const CliResult r = run_cli({"torque", f});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.error, HasSubstr(f + ": header: missing column 'wind_speed_mps'"));
}

TEST_F(TorqueCli, NonNumericValueNamesFileRowAndColumn) {
  const std::string f = write("scada.csv", "t_s,wind_speed_mps\n0,6\n600,fast\n");
  const CliResult r = run_cli({"torque", f});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.error, HasSubstr(f + ": row 2 (line 3), column 'wind_speed_mps': 'fast' is not a number"));
}

TEST_F(TorqueCli, NonFiniteValueIsRejected) {
  const std::string f = write("scada.csv", "t_s,wind_speed_mps,power_kw\n0,6,inf\n");
  const CliResult r = run_cli({"torque", f, "--compare"});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.error, HasSubstr("row 1 (line 2), column 'power_kw': 'inf' is not a finite number"));
}

TEST_F(TorqueCli, NegativeWindSpeedIsRejected) {
  const std::string f = write("scada.csv", "t_s,wind_speed_mps\n0,6\n600,-2.5\n");
  const CliResult r = run_cli({"torque", f});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.error, HasSubstr("row 2 (line 3), column 'wind_speed_mps': -2.5 m/s is negative"));
}

TEST_F(TorqueCli, ImplausibleRotorSpeedIsRejectedForThisTurbine) {
  // paper-2mw: rated 14.8 rpm, so anything above 1.5 × 14.8 = 22.2 rpm is not a rotor speed.
  const std::string f = write("scada.csv", "t_s,wind_speed_mps,rotor_speed_rpm\n0,8,1480\n");
  const CliResult r = run_cli({"torque", f});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.error, HasSubstr("row 1 (line 2), column 'rotor_speed_rpm': 1480 rpm is beyond any "
                                 "plausible rotor speed"));
}

TEST_F(TorqueCli, MalformedDrivetrainFileNamesTheKey) {
  const std::string scada = write("scada.csv", "t_s,wind_speed_mps\n0,6\n");
  const std::string d = write("turbine.toml", "base = \"paper-2mw\"\n[turbine]\ncut_in_wind_mps = \"low\"\n");
  const CliResult r = run_cli({"torque", scada, "--drivetrain", d});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.error, HasSubstr(d + ":3:"));
  EXPECT_THAT(r.error, HasSubstr("key 'turbine.cut_in_wind_mps': expected a number >= 0"));
}

TEST_F(TorqueCli, MissingFileAndBadMappingAreErrorsNotCrashes) {
  CliResult r = run_cli({"torque", (dir_ / "absent.csv").string()});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.error, HasSubstr("absent.csv: cannot open"));
  const std::string f = write("scada.csv", "t_s,wind_speed_mps\n0,6\n");
  r = run_cli({"torque", f, "--columns", "speed=WS"});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.error, HasSubstr("--columns: column mapping: unknown field 'speed'"));
}

TEST_F(TorqueCli, CompareAgainstMeasuredTorqueGivesTheHandCalculatedMape) {
  // Arrange: the paper's check point with its published torque as the measurement.
  // By hand (paper-2mw: ρ = 1.255, R = 41 m, Heier surface at s·λ, s = 1.00873):
  //   ω = 8.33·2π/60 = 0.872316 rad/s, λ = ω·41/6.75 = 5.29851, s·λ = 5.34477
  //   1/λi = 1/5.34477 − 0.035 = 0.152099; Cp = 0.5176·(116·0.152099 − 5)·e^(−21·0.152099)
  //        + 0.0068·5.34477 = 0.304687
  //   T = ½·1.255·π·41²·6.75³·0.304687 / 0.872316 = 355 978 N·m
  //   error = |355 978 − 361 747| / 361 747 = 1.595 %
  const std::string f = write("scada.csv",
                              "t_s,wind_speed_mps,rotor_speed_rpm,torque_nm\n"
                              "0,6.75,8.33,361747\n"
                              "600,3.0,0.0,0\n");
  // Act
  const CliResult r = run_cli({"torque", f, "--compare"});
  // Assert: one row counted (the second is below cut-in), in region 2.
  EXPECT_EQ(r.exit_code, 0) << r.error;
  EXPECT_THAT(r.out, HasSubstr("355978"));
  EXPECT_THAT(r.out, HasSubstr("2               1      1.59"));
  EXPECT_THAT(r.out, HasSubstr("all             1      1.59"));
}

TEST_F(TorqueCli, JsonOutputCarriesEveryRowAndTheSummary) {
  const std::string f = write("scada.csv",
                              "t_s,wind_speed_mps,rotor_speed_rpm,torque_nm\n"
                              "0,6.75,8.33,361747\n"
                              "600,15,14.8,1230000\n");
  const CliResult r = run_cli({"torque", f, "--compare", "--json"});
  EXPECT_EQ(r.exit_code, 0) << r.error;
  EXPECT_THAT(r.out, HasSubstr("\"region\":\"2\""));
  EXPECT_THAT(r.out, HasSubstr("\"region\":\"3\""));
  EXPECT_THAT(r.out, HasSubstr("\"rows_in_operation\":2"));
}

}  // namespace
