// `drivetwin torque` end to end, in-process (so it also runs under qemu-aarch64):
// bad SCADA files and bad descriptions in a temp dir give one message naming the
// file, row and column (or key) and a non-zero exit; a good file gives the MAPE
// of a hand calculation.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "support/run_command.hpp"

namespace {

using test_support::CommandResult;
using test_support::run_command;

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
  const CommandResult r = run_command({"torque", f});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.error, HasSubstr(f + ": header: missing column 'wind_speed_mps'"));
}

TEST_F(TorqueCli, NonNumericValueNamesFileRowAndColumn) {
  // A bad row is counted, named and skipped (app/wind/scada_rows.hpp): exit 2, row 1 kept.
  const std::string f = write("scada.csv", "t_s,wind_speed_mps\n0,6\n600,fast\n");
  const CommandResult r = run_command({"torque", f});
  EXPECT_EQ(r.exit_code, 2) << r;
  EXPECT_THAT(r.err,
              HasSubstr(f + ": row 2 (line 3), column 'wind_speed_mps': 'fast' is not a number"));
  EXPECT_THAT(r.out, HasSubstr("       1              0     6.000"));
}

TEST_F(TorqueCli, NonFiniteValueIsRejected) {
  // The only row rejected: nothing to report, an error (exit 1) naming it.
  const std::string f = write("scada.csv", "t_s,wind_speed_mps,power_kw\n0,6,inf\n");
  const CommandResult r = run_command({"torque", f, "--compare"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.error, HasSubstr("none of the 1 data rows is usable"));
  EXPECT_THAT(r.error,
              HasSubstr("row 1 (line 2), column 'power_kw': 'inf' is not a finite number"));
}

TEST_F(TorqueCli, NegativeWindSpeedIsRejected) {
  const std::string f = write("scada.csv", "t_s,wind_speed_mps\n0,6\n600,-2.5\n");
  const CommandResult r = run_command({"torque", f});
  EXPECT_EQ(r.exit_code, 2) << r;
  EXPECT_THAT(r.err, HasSubstr("row 2 (line 3), column 'wind_speed_mps' (wind_speed_mps): -2.5 "
                               "m/s is negative; a wind speed is >= 0; row skipped"));
  EXPECT_THAT(r.err, HasSubstr("1 row rejected (non-numeric or ragged 0, time 0, rotor speed 0, "
                               "wind 1, other out of range 0)"));
}

TEST_F(TorqueCli, ImplausibleRotorSpeedIsRejectedForThisTurbine) {
  // paper-2mw: rated 14.8 rpm, so anything above 1.5 × 14.8 = 22.2 rpm is not a rotor speed.
  const std::string f = write("scada.csv", "t_s,wind_speed_mps,rotor_speed_rpm\n0,8,1480\n");
  const CommandResult r = run_command({"torque", f});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.error, HasSubstr("row 1 (line 2), column 'rotor_speed_rpm' (rotor_speed_rpm): 1480 "
                                 "rpm is beyond any plausible rotor speed"));
}

TEST_F(TorqueCli, MalformedDrivetrainFileNamesTheKey) {
  const std::string scada = write("scada.csv", "t_s,wind_speed_mps\n0,6\n");
  const std::string d =
      write("turbine.toml", "base = \"paper-2mw\"\n[turbine]\ncut_in_wind_mps = \"low\"\n");
  const CommandResult r = run_command({"torque", scada, "--drivetrain", d});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.error, HasSubstr(d + ":3:"));
  EXPECT_THAT(r.error, HasSubstr("key 'turbine.cut_in_wind_mps': expected a number >= 0"));
}

TEST_F(TorqueCli, MissingFileAndBadMappingAreErrorsNotCrashes) {
  CommandResult r = run_command({"torque", (dir_ / "absent.csv").string()});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.error, HasSubstr("absent.csv: cannot open"));
  const std::string f = write("scada.csv", "t_s,wind_speed_mps\n0,6\n");
  r = run_command({"torque", f, "--columns", "speed=WS"});
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
  const CommandResult r = run_command({"torque", f, "--compare"});
  // Assert: one row counted (the second is below cut-in), in region 2.
  EXPECT_EQ(r.exit_code, 0) << r.error;
  EXPECT_THAT(r.out, HasSubstr("355978"));
  EXPECT_THAT(r.out, HasSubstr("2               1      1.59"));
  EXPECT_THAT(r.out, HasSubstr("all             1      1.59"));
}

TEST_F(TorqueCli, ImplausibleOrNonNumericTemperatureAndYawErrorNameFileRowAndColumn) {
  const std::string header =
      "t_s,wind_speed_mps,rotor_speed_rpm,power_kw,ambient_temperature_c,yaw_error_deg\n";
  CommandResult r =
      run_command({"torque", write("hot.csv", header + "0,6,9,300,12,1\n600,6,9,300,75,1\n")});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("hot.csv: row 2 (line 3), column 'ambient_temperature_c' "
                               "(ambient_temperature_c): 75 degC"));
  r = run_command({"torque", write("text.csv", header + "0,6,9,300,mild,1\n")});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(
      r.error,
      HasSubstr(
          "text.csv: row 1 (line 2), column 'ambient_temperature_c': 'mild' is not a number"));
  r = run_command({"torque", write("yaw.csv", header + "0,6,9,300,12,200\n")});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(
      r.error,
      HasSubstr("yaw.csv: row 1 (line 2), column 'yaw_error_deg' (yaw_error_deg): 200 deg"));
}

TEST_F(TorqueCli, WithoutATemperatureColumnTheDensityIsConstantAndTheOutputSaysSo) {
  const CommandResult r = run_command(
      {"torque", write("s.csv", "t_s,wind_speed_mps,rotor_speed_rpm,power_kw\n0,6.75,8.33,300\n"),
       "--compare", "--no-rows"});
  EXPECT_EQ(r.exit_code, 0) << r.error;
  EXPECT_THAT(r.out, HasSubstr("air density: constant 1.255 kg/m3"));
}

TEST_F(TorqueCli, PowerReferenceComparesTheElectricalSideEstimateWithMeasuredPowerOverSpeed) {
  // Arrange: paper-2mw with η = 0.9 and P_0 = 20 kW; the check point's rotor torque
  // 355 978 N·m (hand calculation above) at ω = 0.872316 rad/s and 10 °C at 0 m:
  //   ρ(10 °C) = 101 325 / (287.05287 · 283.15) = 1.246632 kg/m³ instead of 1.255:
  //   T = 355 978 · 1.246632/1.255 = 353 604 N·m
  //   estimate P_el = 0.9 · 353 604 · 0.872316 − 20 000 = 257 609 W
  //   measured 280 kW → error = (257 609 − 280 000)/280 000 = −8.00 %
  const std::string toml =
      write("t.toml",
            "format = \"drivetwin-drivetrain/1\"\nbase = \"paper-2mw\"\nname = \"t\"\n"
            "[turbine]\ndrivetrain_efficiency = 0.9\n"
            "[turbine.corrections]\nno_load_loss_w = 20000.0\n");
  const std::string f = write("s.csv",
                              "t_s,wind_speed_mps,rotor_speed_rpm,power_kw,ambient_temperature_c\n"
                              "0,6.75,8.33,280,10\n");
  // Act
  const CommandResult r = run_command({"torque", f, "--compare", "--drivetrain", toml});
  // Assert
  EXPECT_EQ(r.exit_code, 0) << r.error;
  EXPECT_THAT(r.out, HasSubstr("-8.00"));
  EXPECT_THAT(r.out, HasSubstr("all             1      8.00"));
  EXPECT_THAT(r.out, HasSubstr("air density: from the ambient temperature in 1 rows"));
}

TEST_F(TorqueCli, CpTableAboveTheBetzLimitOrABadCorrectionKeyNamesTheKey) {
  const std::string f = write("s.csv", "t_s,wind_speed_mps\n0,6\n");
  const std::string head =
      "format = \"drivetwin-drivetrain/1\"\nbase = \"paper-2mw\"\nname = \"t\"\n";
  CommandResult r = run_command(
      {"torque", f, "--drivetrain",
       write("betz.toml",
             head + "[turbine.cp]\ntable_lambda_min = 4.0\ntable_lambda_max = 15.0\n"
                    "table_cp = [0.1, 0.2, 0.3, 0.7, 0.4, 0.4, 0.4, 0.3, 0.3, 0.2, 0.2, 0.1]\n")});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.error, HasSubstr("turbine.cp.table_cp[3]"));
  EXPECT_THAT(r.error, HasSubstr("Betz limit"));
  r = run_command({"torque", f, "--drivetrain",
                   write("corr.toml", head + "[turbine.corrections]\nno_load_los_w = 1.0\n")});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.error, HasSubstr("turbine.corrections.no_load_los_w"));
  r = run_command({"torque", f, "--drivetrain",
                   write("gain.toml", head + "[turbine.corrections]\nnacelle_wind_gain = -1.0\n")});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.error, HasSubstr("turbine.corrections.nacelle_wind_gain"));
}

TEST_F(TorqueCli, JsonOutputCarriesEveryRowAndTheSummary) {
  const std::string f = write("scada.csv",
                              "t_s,wind_speed_mps,rotor_speed_rpm,torque_nm\n"
                              "0,6.75,8.33,361747\n"
                              "600,15,14.8,1230000\n");
  const CommandResult r = run_command({"torque", f, "--compare", "--json"});
  EXPECT_EQ(r.exit_code, 0) << r.error;
  EXPECT_THAT(r.out, HasSubstr("\"region\":\"2\""));
  EXPECT_THAT(r.out, HasSubstr("\"region\":\"3\""));
  EXPECT_THAT(r.out, HasSubstr("\"rows_in_operation\":2"));
}

}  // namespace
