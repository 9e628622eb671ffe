// Wind-side inputs and results that must not be taken at face value (issue 15): `fit-cp`
// refuses a fitted Cp surface above the Betz limit (printed or written with --update) and
// keeps the description file untouched; `torque` does not class a row without a wind
// speed as "below cut-in" with a torque of 0 when its rotor turns at 10 rpm; one NaN,
// ragged or implausible row neither stops `torque` nor `fit-cp` nor changes their result
// (app/wind/scada_rows.hpp, the policy `damage` follows too).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "config/drivetrain_file.hpp"
#include "model/drivetrain/description.hpp"
#include "model/wind/wind_load.hpp"
#include "support/run_command.hpp"

namespace {

namespace fs = std::filesystem;

using test_support::CommandResult;
using test_support::run_command;

class WindInputs : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           (std::string("drivetwin_wind_inputs_") +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return (dir_ / name).string();
  }
  static std::string slurp(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  fs::path dir_;
};

// SCADA rows of the paper turbine in maximum power tracking (4.5–7.5 m/s, below the
// 7.9 m/s where tracking reaches rated speed): the steady-state rotor speed, and the
// electrical power the wind model gives, times `power_factor`.
std::string tracking_rows(double power_factor) {
  const model::Drivetrain d = model::paper_2mw();
  const model::wind::WindLoad wind(d.turbine);
  std::string csv = "t_s,wind_speed_mps,rotor_speed_rpm,power_kw\n";
  for (int i = 0; i < 120; ++i) {
    const double v = 4.5 + 3.0 * static_cast<double>(i) / 119.0;
    const model::wind::WindLoadOutput o = wind.steady_state(v);
    const double p_kw = wind.electrical_power_w(o.torque_nm, o.rotor_speed_rad_s) / 1e3;
    char row[128];
    std::snprintf(row, sizeof row, "%d,%.6f,%.6f,%.6f\n", 600 * i, v,
                  o.rotor_speed_rad_s * 60.0 / (2.0 * std::numbers::pi), power_factor * p_kw);
    csv += row;
  }
  return csv;
}

TEST_F(WindInputs, FitCpRecoversThePaperSurfaceFromItsOwnPower) {
  // The paper gives Cp_max = 0.48 (drivetrain-2mw.md); fitting c1 and the λ scale to rows
  // generated from that surface gives it back.
  const CommandResult r =
      run_command({"fit-cp", write("own.csv", tracking_rows(1.0)), "--free", "none"});
  ASSERT_EQ(r.exit_code, 0) << r.error;
  const auto at = r.out.find("Cp_max ");
  ASSERT_NE(at, std::string::npos) << r.out;
  EXPECT_NEAR(std::stod(r.out.substr(at + 7)), 0.48, 0.01) << r.out;
}

TEST_F(WindInputs, FitCpRefusesASurfaceAboveTheBetzLimitAndWritesNothing) {
  // Arrange: the same rows with 1.6 × the power (a power column that is not this rotor's):
  // the fit would need Cp_max ≈ 0.48 · 1.6 = 0.77 > 16/27.
  const std::string csv = write("inflated.csv", tracking_rows(1.6));
  const std::string desc = write("paper.toml", app::config::to_toml(model::paper_2mw()));
  const std::string before = slurp(desc);
  // Act
  const CommandResult r = run_command({"fit-cp", csv, "--free", "none", "--update", desc});
  // Assert
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.error.find("is above the Betz limit 16/27 = 0.5926"), std::string::npos) << r.error;
  EXPECT_EQ(r.out.find("[turbine.cp]"), std::string::npos) << r.out;  // no table printed
  EXPECT_EQ(slurp(desc), before);
}

TEST_F(WindInputs, FitCpSaysAFittedMaximumAtTheBetzLimitRestsOnSuspectRows) {
  // Arrange: 1.175 × the power of paper-2mw's rows: the fit (c1, lambda_scale) reaches
  // Cp_max 0.580, below 16/27 = 0.5926 (1.2 ×: 0.663, refused) but within 3 % of it. No
  // real rotor gets there, so the fit is printed and flagged; the rows' own power is not.
  const std::string csv = write("high.csv", tracking_rows(1.175));
  // Act
  const CommandResult r = run_command({"fit-cp", csv, "--free", "none"});
  const CommandResult plain =
      run_command({"fit-cp", write("own.csv", tracking_rows(1.0)), "--free", "none"});
  // Assert
  ASSERT_EQ(r.exit_code, 0) << r.error;
  EXPECT_NE(r.out.find("# NOTE: the fitted Cp_max 0.5"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("is at the Betz limit 0.5926"), std::string::npos) << r.out;
  ASSERT_EQ(plain.exit_code, 0) << plain.error;
  EXPECT_EQ(plain.out.find("Betz limit"), std::string::npos) << plain.out;
}

TEST_F(WindInputs, ARowWithoutWindButATurningRotorIsNotBelowCutIn) {
  // Arrange: an empty wind cell with the rotor at 10 rpm, then a row at the paper's point.
  const std::string csv =
      write("nowind.csv", "t_s,wind_speed_mps,rotor_speed_rpm\n0,,10\n600,6.75,8.33\n");
  // Act
  const CommandResult text = run_command({"torque", csv});
  const CommandResult json = run_command({"torque", csv, "--json"});
  // Assert: no region, no torque for row 1; row 2 estimated.
  ASSERT_EQ(text.exit_code, 0) << text.error;
  std::istringstream lines(text.out);
  std::string line, row1;
  while (std::getline(lines, line)) {
    if (line.rfind("       1 ", 0) == 0) row1 = line;
  }
  EXPECT_EQ(row1.find("below_cut_in"), std::string::npos) << row1;
  EXPECT_NE(row1.find("no_wind_speed"), std::string::npos) << row1;
  EXPECT_NE(row1.find(" -"), std::string::npos) << row1;
  EXPECT_NE(json.out.find("\"region\":\"no_wind_speed\""), std::string::npos) << json.out;
  EXPECT_NE(json.out.find("\"torque_nm\":null"), std::string::npos) << json.out;
}

// The rows of `csv` with `bad` rows inserted after its good data rows 30, 60 and 90 (data
// rows 31, 62 and 93 of the result). Each bad row has its own t_s between two good ones.
std::string with_bad_rows(const std::string& csv, const std::vector<std::string>& bad) {
  std::istringstream in(csv);
  std::string line, out;
  std::getline(in, line);
  out = line + "\n";
  int good = 0;
  std::size_t next = 0;
  while (std::getline(in, line)) {
    out += line + "\n";
    ++good;
    if (good % 30 == 0 && next < bad.size()) out += bad[next++] + "\n";
  }
  return out;
}

// The lines of `text` that do not contain `skip` (the file's path, the rejected count).
std::string without_lines_containing(const std::string& text, const std::string& skip) {
  std::istringstream in(text);
  std::string line, out;
  while (std::getline(in, line)) {
    if (line.find(skip) == std::string::npos) out += line + "\n";
  }
  return out;
}

TEST_F(WindInputs, ANanRaggedOrImplausibleRowIsCountedNamedAndSkippedByTorqueAndFitCp) {
  // Before: one such row in years of SCADA stopped `torque` and `fit-cp` with its message
  // (`damage` counted it and carried on). Now all three follow one policy: the row is
  // skipped, counted by reason, named on stderr, the command finishes on the other rows
  // and exits 2. The result must be the result of the good rows alone.
  const std::string good = tracking_rows(1.0);
  const std::string clean = write("clean.csv", good);
  const std::string bad = write(
      "bad.csv", with_bad_rows(good, {"18300,6.0,8.0,nan", "36300,6.0,8.0", "54300,80,8.0,300"}));
  for (const std::vector<std::string>& command :
       {std::vector<std::string>{"torque", "--compare", "--no-rows"},
        std::vector<std::string>{"fit-cp", "--free", "none"}}) {
    std::vector<std::string> on_clean{command[0], clean}, on_bad{command[0], bad};
    on_clean.insert(on_clean.end(), command.begin() + 1, command.end());
    on_bad.insert(on_bad.end(), command.begin() + 1, command.end());
    // Act
    const CommandResult reference = run_command(on_clean);
    const CommandResult r = run_command(on_bad);
    // Assert: exit 2, each row named with its row, line, column and what was wrong.
    ASSERT_EQ(reference.exit_code, 0) << reference;
    EXPECT_EQ(r.exit_code, 2) << command[0] << "\n" << r;
    EXPECT_NE(r.err.find(bad + ": row 31 (line 32), column 'power_kw': 'nan' is not a finite "
                               "number; row skipped"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find(bad + ": row 62 (line 63): 3 fields, expected 4 as in the header; row "
                               "skipped"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find(bad + ": row 93 (line 94), column 'wind_speed_mps' (wind_speed_mps): 80 "
                               "m/s"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("3 rows rejected (non-numeric or ragged 2, time 0, rotor speed 0, wind "
                         "1, other out of range 0)"),
              std::string::npos)
        << r.err;
    // The result is that of the 120 good rows, line for line (but the line naming the file).
    EXPECT_EQ(without_lines_containing(r.out, ".csv"),
              without_lines_containing(reference.out, ".csv"))
        << command[0];
    EXPECT_NE(r.out.find("rejected"), std::string::npos) << r.out;
  }
}

}  // namespace
