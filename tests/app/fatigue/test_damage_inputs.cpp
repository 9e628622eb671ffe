// `drivetwin damage` on bad and extreme input, in-process (issue 15): a header-only file,
// a negative --period, an impossible --grade, NaN and ragged rows without --period, torque
// beyond the load spectrum (counted and left out, never clamped), and a component past
// its life ("exceeded since", at the date a hand calculation of its damage rate gives).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "model/fatigue/drivetrain_channels.hpp"
#include "support/run_command.hpp"

namespace {
namespace fs = std::filesystem;
namespace mf = model::fatigue;

using test_support::CommandResult;
using test_support::run_command;

constexpr const char* kHeader = "t_s,wind_speed_mps,rotor_speed_rpm,power_kw,pitch_deg,torque_nm\n";
constexpr double kRated = 1.23e6;  // [N·m] paper-2mw rated torque

class DamageInputs : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           (std::string("drivetwin_damage_inputs_") +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& text) const {
    const fs::path p = dir_ / name;
    std::ofstream(p) << text;
    return p;
  }
  // damage <file> --json <json> [extra...]; the JSON path is dir_/summary.json.
  CommandResult damage(const fs::path& csv, std::vector<std::string> extra = {}) const {
    std::vector<std::string> args{"damage",      csv.string(),
                                  "--cache-dir", (dir_ / "cache").string(),
                                  "--json",      json().string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return run_command(args);
  }
  fs::path json() const { return dir_ / "summary.json"; }
  fs::path dir_;
};

TEST_F(DamageInputs, AHeaderOnlyFileIsAnErrorAndNothingIsWritten) {
  const fs::path csv = write("header.csv", kHeader);
  for (const auto& extra :
       {std::vector<std::string>{}, std::vector<std::string>{"--period", "600"}}) {
    const CommandResult r = damage(csv, extra);
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.error.find("header.csv: no data rows after the header"), std::string::npos)
        << r.error;
    EXPECT_FALSE(fs::exists(json()));
  }
}

TEST_F(DamageInputs, ANegativePeriodAndAnImpossibleGradeAreRefusedBeforeReading) {
  const fs::path csv = write("rows.csv", std::string(kHeader) + "0,12,14,,,1230000\n");
  const CommandResult period = damage(csv, {"--period", "-600"});
  EXPECT_NE(period.exit_code, 0);
  EXPECT_NE(period.error.find("--period: -600 is out of range"), std::string::npos) << period.error;
  const CommandResult grade = damage(csv, {"--grade", "99"});
  EXPECT_NE(grade.exit_code, 0);
  EXPECT_NE(grade.error.find("--grade: 99 is out of range; expected an integer from 1 to 11"),
            std::string::npos)
      << grade.error;
  EXPECT_FALSE(fs::exists(json()));
}

TEST_F(DamageInputs, NanAndRaggedRowsAreNamedWhenThePeriodCannotBeDetected) {
  const fs::path csv =
      write("bad.csv", std::string(kHeader) + "0,nan,10,,,\n600,5,10,,,\n1200,5\n");
  const CommandResult r = damage(csv);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(
      r.error.find("cannot detect the SCADA period: of the first 3 data rows 2 were rejected"),
      std::string::npos)
      << r.error;
  EXPECT_NE(r.error.find("row 1 (line 2), column 'wind_speed_mps': 'nan'"), std::string::npos)
      << r.error;
  EXPECT_NE(r.error.find("row 3 (line 4): 2 fields, expected 6"), std::string::npos) << r.error;
  EXPECT_FALSE(fs::exists(json()));
}

TEST_F(DamageInputs, TorqueBeyondTheSpectrumIsCountedAndLeftOutNeverClamped) {
  // Arrange: 100 ten-minute rows at rated torque and 14 rpm; a copy whose row 51 is a spike
  // at 2 × rated; a copy with that row left out. 10 × rated is beyond three times rated,
  // the SCADA plausibility limit, and rejected before the spectrum is asked.
  std::string good, spike, gap;
  for (int i = 0; i < 100; ++i) {
    const std::string t = std::to_string(600 * i);
    good += t + ",12,14,,,1230000\n";
    spike += t + (i == 50 ? ",12,14,,,2460000\n" : ",12,14,,,1230000\n");
    if (i != 50) gap += t + ",12,14,,,1230000\n";
  }
  const fs::path with_spike = write("spike.csv", kHeader + spike);
  const fs::path without = write("gap.csv", kHeader + gap);
  // Act
  const CommandResult s = damage(with_spike);
  std::ifstream in_s(json());
  const nlohmann::json js = nlohmann::json::parse(in_s);
  const CommandResult g = damage(without, {"--period", "600"});
  std::ifstream in_g(json());
  const nlohmann::json jg = nlohmann::json::parse(in_g);
  // Assert: the spike is counted, named, not accumulated; the exit says rows were rejected.
  EXPECT_EQ(s.exit_code, 2);
  EXPECT_EQ(js["rows"]["rejected_beyond_spectrum"], 1);
  EXPECT_EQ(js["rows"]["used"], 99);
  EXPECT_NE(s.out.find("1 rows beyond the load spectrum"), std::string::npos) << s.out;
  EXPECT_NE(
      js["issues"][0]["message"].get<std::string>().find("rotor torque 2.46e+06 N·m (2.00 x rated"),
      std::string::npos)
      << js["issues"];
  for (std::size_t c = 0; c < js["channels"].size(); ++c) {
    EXPECT_DOUBLE_EQ(js["channels"][c]["damage"].get<double>(),
                     jg["channels"][c]["damage"].get<double>());
  }
  EXPECT_EQ(g.exit_code, 0);
  // All rows at 2 × rated: nothing usable, an error, not a damage of zero.
  std::string all_spike;
  for (int i = 0; i < 10; ++i) all_spike += std::to_string(600 * i) + ",12,14,,,2460000\n";
  fs::remove(json());
  const CommandResult a = damage(write("all.csv", kHeader + all_spike));
  EXPECT_EQ(a.exit_code, 1);
  EXPECT_NE(a.error.find("none of the 10 data rows is usable"), std::string::npos) << a.error;
  EXPECT_FALSE(fs::exists(json()));
  // 10 × rated: the plausibility limit names it.
  const CommandResult ten =
      damage(write("ten.csv", std::string(kHeader) + "0,12,14,,,1230000\n"
                                                     "600,12,14,,,12300000\n"
                                                     "1200,12,14,,,1230000\n"));
  EXPECT_EQ(ten.exit_code, 2);
  EXPECT_NE(ten.out.find("rejected 1"), std::string::npos) << ten.out;
}

TEST_F(DamageInputs, BearingLivesFromAssumedRatingsSaySoAndCatalogueRatingsDoNot) {
  // Arrange: a copy of paper-2mw without dynamic_rating_n (C from the geometry, ISO 281) and
  // one with a catalogue rating for every bearing.
  const fs::path csv = write("rows.csv", std::string(kHeader) +
                                             "0,12,14,,,1230000\n"
                                             "600,12,14,,,1230000\n");
  std::string ratings = "base = \"paper-2mw\"\nname = \"rated\"\n";
  std::string unrated = "base = \"paper-2mw\"\nname = \"unrated\"\n";
  for (const auto& b : model::paper_2mw().bearings) {
    ratings += "[[bearings]]\nid = \"" + b.id + "\"\ndynamic_rating_n = 2.0e6\n";
    unrated += "[[bearings]]\nid = \"" + b.id + "\"\ndynamic_rating_n = 0.0\n";
  }
  const fs::path toml = write("rated.toml", ratings);
  const fs::path toml_unrated = write("unrated.toml", unrated);
  // Act
  const CommandResult assumed = damage(csv, {"--drivetrain", toml_unrated.string()});
  const CommandResult given = damage(csv, {"--drivetrain", toml.string()});
  // Assert
  ASSERT_EQ(assumed.exit_code, 0) << assumed.error;
  EXPECT_NE(assumed.out.find("# * assumed: no dynamic_rating_n in the description"),
            std::string::npos)
      << assumed.out;
  ASSERT_EQ(given.exit_code, 0) << given.error;
  EXPECT_EQ(given.out.find("assumed"), std::string::npos) << given.out;
  EXPECT_NE(given.out.find(model::paper_2mw().bearings.front().id + " 2000 "), std::string::npos)
      << given.out;
}

TEST_F(DamageInputs, AComponentPastItsLifeSaysExceededSinceTheDateItsDamageReachedOne) {
  // Arrange: daily rows (period 1 day) at rated torque and 14 rpm from 2020-01-01. Hand value
  // of the sun's contact damage per day, independent of the history code: 86 400·14/60 rotor
  // revolutions, 3 planets · 99/21 sun contacts per revolution, at the stress of the
  // quasi-static rated mesh force: d = n/N(σ). D reaches 1 on row k = ceil(1/d) (1-based).
  const mf::ChannelSet cs(model::paper_2mw(), mf::ChannelOptions{});
  std::size_t c_sun = 0;
  while (!(cs.channel(c_sun).component == "sun" &&
           cs.channel(c_sun).mode == mf::FailureMode::kContact))
    ++c_sun;
  const double sigma = cs.stress(c_sun, 0, cs.quasi_static_loads(kRated));
  const double per_day =
      86400.0 * 14.0 / 60.0 * 3.0 * 99.0 / 21.0 / cs.channel(c_sun).curve.cycles_to_failure(sigma);
  const auto k = static_cast<long long>(std::ceil(1.0 / per_day));
  const double t0 = 1577836800.0;  // 2020-01-01T00:00:00Z
  std::string rows;
  for (long long i = 0; i < k + 3; ++i)
    rows += std::to_string(static_cast<long long>(t0) + 86400 * i) + ",12,14,,,1230000\n";
  // Act
  const CommandResult r = damage(write("life.csv", kHeader + rows));
  std::ifstream in(json());
  const nlohmann::json j = nlohmann::json::parse(in);
  // Assert
  ASSERT_EQ(r.exit_code, 0) << r.error;
  const nlohmann::json* sun = nullptr;
  for (const auto& c : j["channels"]) {
    if (c["component"] == "sun" && c["mode"] == "contact") sun = &c;
  }
  ASSERT_NE(sun, nullptr);
  EXPECT_GT((*sun)["damage"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ((*sun)["exceeded_since_t_s"].get<double>(),
                   t0 + 86400.0 * static_cast<double>(k - 1));
  EXPECT_TRUE((*sun)["rul_years"].is_null() || (*sun)["rul_years"].get<double>() == 0.0);
  // The text: "exceeded" in the life columns, and the date.
  EXPECT_NE(r.out.find("sun       -                contact"), std::string::npos);
  const auto line = r.out.find("sun       -                contact");
  EXPECT_NE(r.out.substr(line, 120).find("exceeded"), std::string::npos) << r.out.substr(line, 120);
  char date[32];
  const std::time_t t = static_cast<std::time_t>(t0 + 86400.0 * static_cast<double>(k - 1));
  std::tm tm{};
  gmtime_r(&t, &tm);
  std::strftime(date, sizeof date, "%Y-%m-%d", &tm);
  EXPECT_NE(r.out.find(std::string("PAST ITS LIFE: sun contact: D = ")), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find(std::string("life exceeded since ") + date), std::string::npos) << r.out;
}

TEST_F(DamageInputs, DamageCheckNamesABadRowAmongTheComparedOnesBeforeBuildingTheSpectrum) {
  // damage-check compares the online accumulator with history mode over the first --rows
  // rows, so each is needed. Before: the dynamics spectrum was built (minutes), then the
  // command said "only 5 of the first 6 rows are usable" without naming the row. Now the
  // rows are read first, through the SCADA rows policy, and the bad one is named at once.
  const std::string good = "0,8,10,1000,0,500000\n";
  std::string rows = kHeader;
  for (int i = 0; i < 6; ++i) {
    std::string row = good;
    row.replace(0, 1, std::to_string(600 * i));
    if (i == 2) row = "1200,8,10,1000,0,nan\n";
    if (i == 4) row = "2400,8,80,1000,0,500000\n";  // 80 rpm: beyond 1.5 x rated (22.2)
    rows += row;
  }
  const fs::path csv = write("check.csv", rows);
  // Act
  const CommandResult r = run_command({"damage-check", csv.string(), "--rows", "6"});
  // Assert
  EXPECT_EQ(r.exit_code, 1) << r;
  EXPECT_NE(r.error.find("row 3 (line 4), column 'torque_nm': 'nan' is not a finite number"),
            std::string::npos)
      << r;
  EXPECT_NE(r.error.find("row 5 (line 6), column 'rotor_speed_rpm' (rotor_speed_rpm): 80 rpm"),
            std::string::npos)
      << r;
  EXPECT_NE(r.error.find("2 rows rejected"), std::string::npos) << r;
  EXPECT_EQ(r.err.find("building the dynamics load spectrum"), std::string::npos) << r.err;
  // A file with fewer rows than --rows: said too, before the spectrum.
  const CommandResult few = run_command({"damage-check", csv.string(), "--rows", "7"});
  EXPECT_EQ(few.exit_code, 1) << few;
  EXPECT_NE(few.error.find("6 data rows; --rows asks for 7"), std::string::npos) << few;
}

}  // namespace
