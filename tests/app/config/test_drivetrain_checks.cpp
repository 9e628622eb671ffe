// The physical validation of drivetrain descriptions (app/config/drivetrain_checks.hpp),
// through the file parser as every command meets it: the impossible gearboxes
// (a 22-tooth sun with 39-tooth planets in a 99-tooth ring, 7 planets, a 3-tooth sun, an
// 89° helix, a profile shift of 5), a Cp above Betz and an inconsistent rated point are
// refused naming the file, line and key; the reference gearbox and the profile-shifted
// equivalent of the 22-tooth sun (hand calculation below) pass.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "config/drivetrain_checks.hpp"
#include "config/drivetrain_file.hpp"
#include "model/drivetrain/description.hpp"
#include "support/run_command.hpp"

namespace {

using app::config::DrivetrainFileError;
using app::config::parse_drivetrain;

std::string variant(const std::string& body) {
  return "format = \"drivetwin-drivetrain/1\"\nbase = \"paper-2mw\"\nname = \"variant\"\n" + body;
}

// The parser's message for `body` on the paper-2mw base ("" when accepted).
std::string refusal(const std::string& body) {
  try {
    (void)parse_drivetrain(variant(body), "variant.toml");
  } catch (const DrivetrainFileError& e) {
    return e.what();
  }
  return "";
}

TEST(DrivetrainChecks, TheBuiltInDescriptionsPass) {
  for (const auto& name : app::config::builtin_drivetrain_names()) {
    EXPECT_TRUE(app::config::check_drivetrain(app::config::load_drivetrain(name)).empty()) << name;
  }
}

TEST(DrivetrainChecks, ASunThatCannotMeshAtThePlanetsCentreDistanceIsRefused) {
  // z_ring − z_sun = 99 − 22 = 77 ≠ 2·39: a_sun-planet = 17·(22 + 39)/2 = 518.5 mm against
  // a_ring-planet = 17·(99 − 39)/2 = 510 mm.
  const std::string e = refusal("[[gears]]\nid = \"sun\"\nteeth = 22\n");
  EXPECT_NE(e.find("variant.toml: key 'stages[0].gears': the planets cannot mesh"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("sun-planet 518.5 mm, ring-planet 510 mm"), std::string::npos) << e;
}

TEST(DrivetrainChecks, TheProfileShiftedEquivalentOfThatSunIsAccepted) {
  // Hand calculation (ISO 21771): the sun–planet pair must work at a_w = 510 mm instead of
  // a = 518.5 mm: cos α_w = 518.5·cos 20°/510 → α_w = 17.185°; x_sun + x_planet =
  // (inv α_w − inv 20°)·(22 + 39)/(2·tan 20°) = −0.4671. One planet: (99 + 22)/N is an
  // integer only for N = 1 or 11 (equal spacing, next test).
  const std::string one_planet = "[[stages]]\nid = \"planetary\"\nplanets = 1\n";
  EXPECT_EQ(refusal(one_planet + "[[gears]]\nid = \"sun\"\nteeth = 22\nprofile_shift = -0.4671\n"),
            "");
  // ... and a shift off by 0.05 misses the centre distance by more than 0.01·m_n.
  EXPECT_NE(refusal(one_planet + "[[gears]]\nid = \"sun\"\nteeth = 22\nprofile_shift = -0.41\n")
                .find("cannot mesh"),
            std::string::npos);
  // With three planets the shifted sun meshes but cannot be assembled equally spaced.
  EXPECT_NE(refusal("[[gears]]\nid = \"sun\"\nteeth = 22\nprofile_shift = -0.4671\n")
                .find("(z_ring + z_sun) / N = 121 / 3 is not an integer"),
            std::string::npos);
}

TEST(DrivetrainChecks, SevenPlanetsOverlapAndFiveCannotBeEquallySpaced) {
  // Neighbouring planet centres 2·510·sin(π/7) = 442.6 mm apart; a planet's tip circle is
  // 17·(39 + 2) = 697 mm across.
  const std::string seven = refusal("[[stages]]\nid = \"planetary\"\nplanets = 7\n");
  EXPECT_NE(seven.find("variant.toml:6:11: key 'stages[0].planets': 7 planets overlap"),
            std::string::npos)
      << seven;
  EXPECT_NE(seven.find("442.6 mm apart"), std::string::npos) << seven;
  EXPECT_NE(seven.find("697 mm"), std::string::npos) << seven;
  // 5 planets: 2·510·sin 36° = 599.5 mm < 697 mm also overlap; 4 clear (721 mm) and
  // (99 + 21)/4 = 30; a 2-planet carrier with (99 + 21)/2 = 60 too. Assembly: none of
  // these fail it, so a 99/39/21 stage with planets that clear but do not divide 120 needs
  // another ring: 98 teeth with a 20-tooth sun (98 − 20 = 78 = 2·39), (98 + 20)/4 = 29.5.
  EXPECT_EQ(refusal("[[stages]]\nid = \"planetary\"\nplanets = 4\n"), "");
  const std::string spacing = refusal(
      "[[stages]]\nid = \"planetary\"\nplanets = 4\n[[gears]]\nid = \"ring\"\nteeth = 98\n"
      "[[gears]]\nid = \"sun\"\nteeth = 20\n");
  EXPECT_NE(spacing.find("4 planets cannot be equally spaced"), std::string::npos) << spacing;
  EXPECT_NE(spacing.find("118 / 4 is not an integer"), std::string::npos) << spacing;
}

TEST(DrivetrainChecks, UndercutTeethAreRefusedWithThePracticalLimit) {
  // The 3-tooth sun. Spur, 20°, x = 0: z_min = 2/sin²20° = 17.1, practical 14.
  const std::string sun = refusal("[[gears]]\nid = \"sun\"\nteeth = 3\n");
  EXPECT_NE(sun.find("key 'gears[2].teeth': 3 teeth on gear 'sun'"), std::string::npos) << sun;
  EXPECT_NE(sun.find("expected at least 14"), std::string::npos) << sun;
  // The intermediate pinion g2 (β = 10°): α_t = atan(tan 20°/cos 10°) = 20.28°,
  // z_min = 2·cos 10°/sin²α_t = 16.4, practical round(5/6·16.4) = 14: 13 refused, 14 not.
  EXPECT_NE(refusal("[[gears]]\nid = \"g2\"\nteeth = 13\n").find("13 teeth on gear 'g2'"),
            std::string::npos);
  EXPECT_EQ(refusal("[[gears]]\nid = \"g2\"\nteeth = 14\n"), "");
  // A positive profile shift lifts the limit: x = 0.3 → z_min = 11.5, practical 10.
  EXPECT_EQ(refusal("[[gears]]\nid = \"g2\"\nteeth = 13\nprofile_shift = 0.3\n"), "");
}

TEST(DrivetrainChecks, HelixPressureAngleAndProfileShiftOutsideTheirRangesAreRefused) {
  const std::string helix = refusal("[[stages]]\nid = \"intermediate\"\nhelix_angle_deg = 89.0\n");
  EXPECT_NE(helix.find("key 'stages[1].helix_angle_deg': 89 deg; expected 0 to 45 deg"),
            std::string::npos)
      << helix;
  const std::string alpha = refusal("[[stages]]\nid = \"high_speed\"\npressure_angle_deg = 60.0\n");
  EXPECT_NE(alpha.find("key 'stages[2].pressure_angle_deg': 60 deg; expected 10 to 35 deg"),
            std::string::npos)
      << alpha;
  const std::string shift = refusal("[[gears]]\nid = \"g2\"\nprofile_shift = 5.0\n");
  EXPECT_NE(shift.find("variant.toml:6:17: key 'gears[4].profile_shift': 5 on gear 'g2'"),
            std::string::npos)
      << shift;
}

TEST(DrivetrainChecks, APointedToothTipIsRefused) {
  // g4: 26 teeth, m_n 14 mm. A spur check of the tip-thickness formula by hand: z = 20,
  // x = 0, m = 1: d_a = 22, α_a = acos(20·cos 20°/22) = 31.32°, s_a = 22·(π/2/20 + inv 20°
  // − inv 31.32°) = 0.695 m. With x = 1.4 on g4 the tip thins below 0.2·m_n = 2.8 mm.
  const std::string e = refusal("[[gears]]\nid = \"g4\"\nprofile_shift = 1.4\n");
  EXPECT_NE(e.find("key 'gears[6].profile_shift': 1.4 on gear 'g4' (26 teeth) leaves a tip"),
            std::string::npos)
      << e;
  EXPECT_EQ(refusal("[[gears]]\nid = \"g4\"\nprofile_shift = 0.5\n"), "");
}

TEST(DrivetrainChecks, CpAboveBetzAndAnInconsistentRatedPointAreRefused) {
  const std::string cp = refusal("[turbine]\ncp_max = 0.7\n");
  EXPECT_NE(cp.find("key 'turbine.cp_max': 0.7; expected at most the Betz limit"),
            std::string::npos)
      << cp;
  // The surface itself: c1 × 1.5 lifts the paper surface's maximum (0.48) by half of all but
  // its c6·λ term, well above 16/27.
  const model::Drivetrain paper = model::paper_2mw();
  std::string c = "[turbine.cp]\nc = [";
  for (std::size_t i = 0; i < paper.turbine.cp.c.size(); ++i) {
    c += (i ? ", " : "") + std::to_string(paper.turbine.cp.c[i] * (i == 0 ? 1.5 : 1.0));
  }
  const std::string surface = refusal(c + "]\n");
  const std::string prefix = "key 'turbine.cp': the surface's maximum Cp is ";
  ASSERT_NE(surface.find(prefix), std::string::npos) << surface;
  EXPECT_GT(std::stod(surface.substr(surface.find(prefix) + prefix.size())), 0.65) << surface;
  // Rated torque with a digit too many: η·T·ω = 1 × 1.23e7 × 14.8·2π/60 = 1.906e7 W ≠ 2 MW.
  const std::string rated = refusal("[turbine]\nrated_torque_nm = 1.23e7\n");
  EXPECT_NE(rated.find("key 'turbine.rated_power_w': 2e+06 W"), std::string::npos) << rated;
  EXPECT_NE(rated.find("1.906e+07 W"), std::string::npos) << rated;
}

TEST(DrivetrainChecks, MaterialsOutsideIso6336RangesAreRefused) {
  const std::string e = refusal("[[materials]]\nid = \"17CrNiMo6\"\nsigma_hlim_mpa = 15000.0\n");
  EXPECT_NE(e.find("materials[0].sigma_hlim_mpa': 1.5e+04; expected 200 to 2000 MPa"),
            std::string::npos)
      << e;
}

TEST(DrivetrainChecks, EveryCommandRefusesTheImpossibleGearboxWritingNothing) {
  // Arrange: the 22-tooth sun in a file, as a user passes it with --drivetrain.
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "drivetwin_checks_cli";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path toml = dir / "sun22.toml";
  std::ofstream(toml) << variant("[[gears]]\nid = \"sun\"\nteeth = 22\n");
  const fs::path csv = dir / "rows.csv";
  std::ofstream(csv) << "t_s,wind_speed_mps,rotor_speed_rpm,torque_nm\n0,12,14,1230000\n";
  const std::vector<std::vector<std::string>> commands{
      {"drivetrain", "--drivetrain", toml.string()},
      {"damage", csv.string(), "--drivetrain", toml.string(), "--json", (dir / "d.json").string(),
       "--cache-dir", (dir / "cache").string()},
      {"simulate", "--drivetrain", toml.string(), "--rpm", "8.33", "--torque", "361747", "--out",
       (dir / "sim").string()}};
  for (const auto& args : commands) {
    // Act
    const test_support::CommandResult r = test_support::run_command(args);
    const std::string& out = r.out;
    // Assert: refused at the key, non-zero, nothing printed as a result, nothing written.
    EXPECT_EQ(r.exit_code, 1) << args[0];
    EXPECT_NE(r.error.find("sun22.toml"), std::string::npos) << args[0] << ": " << r.error;
    EXPECT_NE(r.error.find("key 'stages[0].gears': the planets cannot mesh"), std::string::npos)
        << args[0] << ": " << r.error;
    EXPECT_EQ(out.find("[turbine]"), std::string::npos) << args[0];
  }
  EXPECT_FALSE(fs::exists(dir / "d.json"));
  EXPECT_FALSE(fs::exists(dir / "sim"));
  fs::remove_all(dir);
}

}  // namespace
