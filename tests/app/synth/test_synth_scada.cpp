// `drivetwin synth-scada` end to end, in-process through app::cli::run: the turbulent mode
// (--turbulence) writes 1-s rows whose 10-minute means are what --out-10min writes; with no
// turbulence the rotor model sits at the wind load model's steady operating point; a seed
// reproduces a file byte for byte; 10-minute winds come from a file (or the built-in day);
// bad inputs stop with the file, row and column.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "model/drivetrain/description.hpp"
#include "model/wind/wind_load.hpp"
#include "support/run_command.hpp"
#include "wind/synthetic_wind.hpp"

namespace {
namespace fs = std::filesystem;

struct SynthResult {
  int exit_code = 0;
  std::string error;
};

SynthResult run_synth(const std::vector<std::string>& args) {
  const test_support::CommandResult r = test_support::run_command(args);
  return {r.exit_code, r.error};
}

struct Row {
  double t = 0, wind = 0, rpm = 0, kw = 0, torque = 0, pitch = 0;
};

std::vector<Row> read_rows(const fs::path& path, std::string* header = nullptr) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  if (header) *header = line;
  std::vector<Row> rows;
  while (std::getline(in, line)) {
    Row r;
    char c = 0;
    std::istringstream f(line);
    f >> r.t >> c >> r.wind >> c >> r.rpm >> c >> r.kw >> c >> r.torque >> c >> r.pitch;
    rows.push_back(r);
  }
  return rows;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class SynthScada : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           (std::string("drivetwin_synth_") +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string p(const char* name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

TEST_F(SynthScada, TurbulentRowsAverageToTheTenMinuteFile) {
  // Two 10-minute rows (1 200 s) of class A turbulence around the paper's 6.75 m/s.
  const SynthResult r = run_synth({"synth-scada", "--turbulence", "A", "--mean-wind", "6.75",
                                   "--days", std::to_string(1200.0 / 86400.0), "--out", p("1s.csv"),
                                   "--out-10min", p("10min.csv")});
  ASSERT_EQ(r.exit_code, 0) << r.error;
  std::string header;
  const auto fine = read_rows(p("1s.csv"), &header);
  const auto coarse = read_rows(p("10min.csv"));
  EXPECT_EQ(header, "t_s,wind_speed_mps,rotor_speed_rpm,power_kw,torque_nm,pitch_deg");
  ASSERT_EQ(fine.size(), 1200u);
  ASSERT_EQ(coarse.size(), 2u);
  EXPECT_EQ(fine[1].t - fine[0].t, 1.0);
  for (std::size_t k = 0; k < 2; ++k) {
    double wind = 0, torque = 0;
    for (std::size_t i = 600 * k; i < 600 * (k + 1); ++i) {
      wind += fine[i].wind / 600.0;
      torque += fine[i].torque / 600.0;
    }
    EXPECT_EQ(coarse[k].t, fine[600 * k].t);
    // Printed with 3 decimals (wind) and 0.1 N·m (torque).
    EXPECT_NEAR(coarse[k].wind, wind, 2e-3);
    EXPECT_NEAR(coarse[k].torque, torque, 0.2);
    // The row's mean wind is the given mean (cross-fades move it in second order only).
    EXPECT_NEAR(coarse[k].wind, 6.75, 0.15);
  }
  // Turbulence is there, and the disc average (the default) is calmer than the hub point's
  // wind (--point-wind, same seed): σ1 = 0.16·(0.75·6.75 + 5.6) = 1.71 m/s within each row at
  // the hub, of which the 1-s means keep all but the part above 0.5 Hz.
  ASSERT_EQ(run_synth({"synth-scada", "--turbulence", "A", "--mean-wind", "6.75", "--days",
                       std::to_string(1200.0 / 86400.0), "--point-wind", "--out", p("pt.csv")})
                .exit_code,
            0);
  auto sd = [](const std::vector<Row>& rows) {
    double var = 0;
    for (const Row& row : rows) var += (row.wind - 6.75) * (row.wind - 6.75);
    return std::sqrt(var / static_cast<double>(rows.size()));
  };
  const double point = sd(read_rows(p("pt.csv")));
  EXPECT_GT(point, 1.55);
  EXPECT_LT(point, 1.72);
  EXPECT_LT(sd(fine), point);
  EXPECT_GT(sd(fine), 0.6 * point);
}

TEST_F(SynthScada, NoTurbulenceSitsAtTheSteadyOperatingPoint) {
  ASSERT_EQ(run_synth({"synth-scada", "--turbulence", "none", "--mean-wind", "6.75", "--days",
                       std::to_string(1200.0 / 86400.0), "--resolution", "60", "--out", p("a.csv")})
                .exit_code,
            0);
  const auto rows = read_rows(p("a.csv"));
  ASSERT_EQ(rows.size(), 20u);  // two 10-minute rows of ten 60-s rows
  const model::wind::WindLoad load(model::paper_2mw().turbine);
  const auto ref = load.steady_state(6.75);  // λ_opt tracking: 370 048 N·m
  for (const Row& row : rows) {
    EXPECT_NEAR(row.torque / ref.torque_nm, 1.0, 1e-6);
    EXPECT_NEAR(row.rpm, ref.rotor_speed_rad_s * 60.0 / (2.0 * std::numbers::pi), 1e-4);
    EXPECT_EQ(row.wind, 6.75);
  }
}

TEST_F(SynthScada, SameSeedSameFileOtherSeedOther) {
  const std::vector<std::string> base{"synth-scada", "--turbulence", "B", "--days", "0.01"};
  auto with = [&](const char* seed, const std::string& out) {
    auto a = base;
    a.insert(a.end(), {"--seed", seed, "--out", out});
    return run_synth(a).exit_code;
  };
  ASSERT_EQ(with("4", p("a.csv")), 0);
  ASSERT_EQ(with("4", p("b.csv")), 0);
  ASSERT_EQ(with("5", p("c.csv")), 0);
  EXPECT_EQ(slurp(p("a.csv")), slurp(p("b.csv")));
  EXPECT_NE(slurp(p("a.csv")), slurp(p("c.csv")));
}

TEST_F(SynthScada, TenMinuteWindsFromAFileAndFromTheBuiltInDay) {
  std::ofstream(p("in.csv")) << "t_s,wind_speed_mps\n0,5\n600,3\n1800,25\n";
  ASSERT_EQ(run_synth({"synth-scada", "--turbulence", "C", "--from-10min", p("in.csv"),
                       "--resolution", "10", "--out", p("a.csv"), "--out-10min", p("b.csv")})
                .exit_code,
            0);
  const auto coarse = read_rows(p("b.csv"));
  ASSERT_EQ(coarse.size(), 3u);
  EXPECT_EQ(coarse[2].t, 1800.0);    // the gap is kept, not filled
  EXPECT_GT(coarse[0].torque, 0.0);  // 5 m/s: operating
  EXPECT_EQ(coarse[1].torque, 0.0);  // 3 m/s mean: below cut-in, parked
  EXPECT_EQ(coarse[2].torque, 0.0);  // 25 m/s mean: above cut-out, parked
  EXPECT_EQ(coarse[1].rpm, 0.0);
  EXPECT_GT(coarse[1].wind, 0.0);  // the wind is still there
  EXPECT_EQ(read_rows(p("a.csv")).size(), 180u);

  // The built-in Kelmarsh day (its columns, date-time stamps), 144 rows.
  ASSERT_EQ(run_synth({"synth-scada", "--turbulence", "none", "--from-10min",
                       "builtin:kelmarsh-day.csv", "--resolution", "600", "--out", p("k.csv")})
                .exit_code,
            0);
  const auto k = read_rows(p("k.csv"));
  ASSERT_EQ(k.size(), 144u);
  EXPECT_EQ(k[0].t, 1575504000.0);  // 2019-12-05T00:00:00Z
  EXPECT_NEAR(k[0].wind, 7.373, 1e-3);
}

TEST_F(SynthScada, TenMinuteRowsCarryTheTwoScaleWindOrTheSingleAr1) {
  // The steady mode's wind column is the two-scale generator's series for the seed (written with
  // 3 decimals), and --lag1 switches to the single AR(1) w = 1, τ = −600 s/ln(lag1).
  ASSERT_EQ(
      run_synth({"synth-scada", "--days", "2", "--seed", "9", "--out", p("two.csv")}).exit_code, 0);
  ASSERT_EQ(run_synth({"synth-scada", "--days", "2", "--seed", "9", "--lag1", "0.9", "--out",
                       p("one.csv")})
                .exit_code,
            0);
  app::wind::SyntheticWind two(app::wind::SyntheticWindParameters{}, 600.0, 9);
  app::wind::SyntheticWindParameters ar1;
  ar1.slow_weight = 1.0;
  ar1.slow_time_constant_s = -600.0 / std::log(0.9);
  app::wind::SyntheticWind one(ar1, 600.0, 9);
  const auto rows_two = read_rows(p("two.csv")), rows_one = read_rows(p("one.csv"));
  ASSERT_EQ(rows_two.size(), 288u);
  ASSERT_EQ(rows_one.size(), 288u);
  for (std::size_t i = 0; i < rows_two.size(); ++i) {
    EXPECT_NEAR(rows_two[i].wind, two.next(rows_two[i].t), 5.1e-4) << "row " << i;
    EXPECT_NEAR(rows_one[i].wind, one.next(rows_one[i].t), 5.1e-4) << "row " << i;
  }
  const SynthResult bad =
      run_synth({"synth-scada", "--days", "1", "--slow-weight", "0", "--out", p("bad.csv")});
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.error.find("--slow-weight: 0 is out of range; expected a number in (0, 1]"),
            std::string::npos)
      << bad.error;
}

TEST_F(SynthScada, BadInputsNamed) {
  std::ofstream(p("neg.csv")) << "t_s,wind_speed_mps\n0,5\n600,-2\n";
  std::ofstream(p("dup.csv")) << "t_s,wind_speed_mps\n0,5\n300,6\n";
  std::ofstream(p("text.csv")) << "t_s,wind_speed_mps\n0,5\n600,windy\n";
  std::ofstream(p("cols.csv")) << "time,wind\n0,5\n";
  struct Case {
    std::vector<std::string> args;
    std::vector<std::string> says;
  };
  const std::vector<Case> cases{
      {{"--turbulence", "A", "--from-10min", p("neg.csv")},
       {"neg.csv", "row 2", "wind_speed_mps", "-2"}},
      {{"--turbulence", "A", "--from-10min", p("dup.csv")},
       {"dup.csv", "row 2", "t_s", "less than 600 s"}},
      {{"--turbulence", "A", "--from-10min", p("text.csv")},
       {"text.csv", "row 2", "wind_speed_mps"}},
      {{"--turbulence", "A", "--from-10min", p("cols.csv")}, {"cols.csv", "t_s"}},
      {{"--turbulence", "A", "--from-10min", "builtin:nope.csv"}, {"nope.csv"}},
      {{"--turbulence", "D", "--days", "1"}, {"--turbulence", "'D'"}},
      {{"--mean-wind", "6.75", "--days", "1"}, {"--mean-wind", "needs --turbulence"}},
      {{"--resolution", "1", "--days", "1"}, {"--resolution", "needs --turbulence"}},
      {{"--turbulence", "A", "--mean-wind", "-3", "--days", "1"}, {"--mean-wind", "-3"}},
      {{"--turbulence", "A", "--from-10min", p("neg.csv"), "--days", "1"},
       {"--from-10min excludes"}},
      {{"--turbulence", "A", "--mean-wind", "6.75"}, {"--days must be given"}},
      {{"--turbulence", "A", "--mean-wind", "6.75", "--resolution", "7"}, {"--resolution"}},
      {{"--turbulence", "A", "--mean-wind", "6.75", "--rotor-inertia", "0"},
       {"--rotor-inertia: 0 is out of range"}},
      {{"--turbulence", "A", "--mean-wind", "6.75", "--hub-height", "-5"},
       {"--hub-height: -5 is out of range"}},
      {{"--turbulence", "A", "--mean-wind", "6.75", "--from-10min", p("neg.csv")},
       {"--from-10min excludes"}},
      // Options refused while parsing (app/cli/options.hpp); `--days nan` used to be ignored
      // and 11 years written.
      {{"--days", "nan"}, {"--days: 'nan' is not a finite number"}},
      {{"--years", "-1"}, {"--years: -1 is out of range"}},
      {{"--lag1", "1"}, {"--lag1: 1 is out of range; expected a number in (0, 1)"}},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args{"synth-scada", "--out", p("out.csv")};
    args.insert(args.end(), c.args.begin(), c.args.end());
    const SynthResult r = run_synth(args);
    EXPECT_NE(r.exit_code, 0) << c.args[1];
    for (const std::string& s : c.says) EXPECT_NE(r.error.find(s), std::string::npos) << r.error;
  }
}

}  // namespace
