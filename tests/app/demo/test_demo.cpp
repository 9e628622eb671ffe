// `drivetwin demo` end to end, in-process (so it also runs under qemu-aarch64): the
// gearbox stage's printed mesh forces against hand statics (torque / base radius,
// written out here from drivetrain-2mw.md), its point1 lines against the gear
// kinematics, the fatigue stage against the built-in day read here and against
// `drivetwin damage` on the same day, and an unknown stage name giving a clear error.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "data/embedded.hpp"
#include "support/run_command.hpp"

namespace {

using test_support::CommandResult;
using test_support::run_command;

constexpr double kPi = 3.14159265358979323846;

TEST(DemoGearboxStage, MeanMeshForcesMatchTorqueOverBaseRadiusAndPoint1ShowsTheHighSpeedMesh) {
  // Act
  const CommandResult r = run_command({"demo", "--stage", "gearbox"});
  ASSERT_EQ(r.exit_code, 0) << r.error;

  // The input torque the stage printed (wind model at 6.75 m/s, 8.33 rpm), in kN·m.
  const auto at = r.out.find("input torque ");
  ASSERT_NE(at, std::string::npos) << r.out;
  const double torque_nm = std::stod(r.out.substr(at + 13)) * 1e3;
  EXPECT_NEAR(torque_nm, 361747.0, 0.05 * 361747.0);  // the paper's check point, ±5 %

  // Hand statics (drivetrain-2mw.md: z_s 21, z_r 99, m 17 mm, α 20°, 3 planets;
  // helical stages m_n 14 mm, β 10°, 92/21 and 107/26).
  const double cos20 = std::cos(20 * kPi / 180);
  const double t_sun = torque_nm * 21.0 / 120.0;
  const double f_sun_kn = t_sun / (3 * 21 * 0.017 / 2 * cos20) / 1e3;
  const double beta = 10 * kPi / 180;
  const double at_rad = std::atan(std::tan(20 * kPi / 180) / std::cos(beta));
  const double bb = std::atan(std::tan(beta) * std::cos(at_rad));
  const double rb_unit = 0.014 / std::cos(beta) / 2 * std::cos(at_rad) * std::cos(bb);
  const double t_ims = t_sun * 21.0 / 92.0;
  const double f_int_kn = t_ims / (21 * rb_unit) / 1e3;
  const double f_hs_kn = t_ims * 26.0 / 107.0 / (26 * rb_unit) / 1e3;

  std::map<std::string, double> mean_kn;
  std::istringstream lines(r.out);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream in(line);
    std::string id;
    double mean = 0.0;
    if (in >> id >> mean &&
        (id.find("planet") != std::string::npos || id == "intermediate" || id == "high_speed")) {
      mean_kn[id] = mean;
    }
  }
  ASSERT_EQ(mean_kn.size(), 8u) << r.out;
  const double sun_mean =
      (mean_kn["sun_planet_1"] + mean_kn["sun_planet_2"] + mean_kn["sun_planet_3"]) / 3;
  EXPECT_NEAR(sun_mean / f_sun_kn, 1.0, 0.01);
  EXPECT_NEAR(mean_kn["intermediate"] / f_int_kn, 1.0, 0.01);
  EXPECT_NEAR(mean_kn["high_speed"] / f_hs_kn, 1.0, 0.01);

  // point1 (b5 seat, on the hss): every one of the strongest lines printed is a
  // harmonic of the high-speed mesh, z_g4 × hss speed = 26 × 8.33/60 × (120/21)(92/21)(107/26)
  // = 371.88 Hz (drivetrain-2mw.md), within two 0.78 Hz lines.
  const auto p1 = r.out.find("point1");
  ASSERT_NE(p1, std::string::npos);
  const std::string point1 = r.out.substr(p1, r.out.find('\n', p1) - p1);
  const double hss_mesh_hz = 8.33 / 60 * (120.0 / 21.0) * (92.0 / 21.0) * (107.0 / 26.0) * 26.0;
  EXPECT_NEAR(hss_mesh_hz, 371.88, 0.05);
  int lines_seen = 0;
  for (std::size_t pos = point1.find(" Hz "); pos != std::string::npos;
       pos = point1.find(" Hz ", pos + 1)) {
    const std::size_t start = point1.rfind(' ', pos - 1) + 1;
    const double hz = std::stod(point1.substr(start, pos - start));
    const double k = std::round(hz / hss_mesh_hz);
    EXPECT_GE(k, 1.0) << point1;
    EXPECT_NEAR(hz, k * hss_mesh_hz, 1.6) << point1;
    ++lines_seen;
  }
  EXPECT_GE(lines_seen, 3) << point1;
}

// The number printed after `key` in `text` (npos-safe: NaN when absent).
double number_after(const std::string& text, const std::string& key) {
  const auto at = text.find(key);
  if (at == std::string::npos) return std::nan("");
  return std::stod(text.substr(at + key.size()));
}

TEST(DemoFatigueStage, ReadsTheWholeBuiltInDayAndAgreesWithTheDamageCommand) {
  // Act
  const CommandResult r = run_command({"demo", "--stage", "fatigue"});
  ASSERT_EQ(r.exit_code, 0) << r.error;

  // Expected: the day's rows and mean wind, read here from the embedded CSV (Kelmarsh export:
  // the wind speed is the second column; every row of this day is in operation).
  const auto text = app::data::embedded_file("kelmarsh-day.csv");
  ASSERT_TRUE(text.has_value());
  std::istringstream csv{std::string(*text)};
  std::string line;
  std::getline(csv, line);  // header
  double wind_sum = 0.0;
  int rows = 0;
  while (std::getline(csv, line)) {
    if (line.empty()) continue;
    const auto c1 = line.find(',');
    wind_sum += std::stod(line.substr(c1 + 1));
    ++rows;
  }
  ASSERT_EQ(rows, 144);
  EXPECT_EQ(number_after(r.out, "wind ("), 144.0) << r.out;
  EXPECT_NEAR(number_after(r.out, "rows, mean "), wind_sum / rows, 0.006) << r.out;

  // The stage is `drivetwin damage` on the same day through the same wind model: the sun's
  // contact damage agrees to the 4 digits printed.
  const double demo_sun = number_after(r.out, "sun contact damage: ");
  const CommandResult d = run_command(
      {"damage", "builtin:kelmarsh-day.csv", "--torque-from", "wind-steady", "--no-cache"});
  ASSERT_EQ(d.exit_code, 0) << d.error;
  const auto row = d.out.find("\nsun ");
  ASSERT_NE(row, std::string::npos) << d.out;
  std::istringstream sun_row(d.out.substr(row + 1));
  std::string component, detail, mode;
  double damage = 0.0;
  sun_row >> component >> detail >> mode >> damage;
  ASSERT_EQ(mode, "contact");
  EXPECT_NEAR(demo_sun / damage, 1.0, 1e-3) << r.out;

  // Remaining life at one day's rate, by hand: (1 − D)/D days.
  const auto sun_line = r.out.find("  sun contact ");
  ASSERT_NE(sun_line, std::string::npos) << r.out;
  std::istringstream listed(r.out.substr(sun_line));
  std::string word;
  double d_listed = 0.0, rul_years = 0.0;
  listed >> word >> word >> d_listed >> rul_years;
  EXPECT_NEAR(rul_years, (1.0 - damage) / damage / 365.25, 0.01 * rul_years);

  // The bearings at the reference's catalogue C, ISO 281's rating from the geometry beside it
  // (b1: 1 700 kN; by hand 1 194.7 kN, tests/app/fatigue/test_damage_cli.cpp).
  EXPECT_NE(r.out.find("b1 1700 (1195)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("life modification a_ISO"), std::string::npos) << r.out;

  // As the paper observes, the damage concentrates near rated torque.
  const auto near = r.out.find("of the time, ");
  ASSERT_NE(near, std::string::npos) << r.out;
  EXPECT_GT(std::stod(r.out.substr(near + 13)), 50.0) << r.out;
}

TEST(DemoCommand, AnUnknownStageIsNamedInTheErrorAndFails) {
  const CommandResult r = run_command({"demo", "--stage", "no-such-stage"});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.error.find("no-such-stage"), std::string::npos) << r.error;
}

}  // namespace
