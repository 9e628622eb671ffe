// Drivetrain description files (app/config/drivetrain_file.hpp): every field
// survives a write/read round trip, `base` + overrides merge as documented, and
// every bad file is rejected with a message naming the file and the full key.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "config/drivetrain_file.hpp"
#include "model/drivetrain/description.hpp"

namespace {

using app::config::DrivetrainFileError;
using app::config::parse_drivetrain;

void expect_same(double a, double b, const std::string& what) {
  EXPECT_NEAR(a, b, 1e-12 * std::fabs(b)) << what;
}

void expect_equal(const model::Drivetrain& a, const model::Drivetrain& b) {
  EXPECT_EQ(a.name, b.name);
  const auto& ta = a.turbine;
  const auto& tb = b.turbine;
  expect_same(ta.rated_power_w, tb.rated_power_w, "rated_power_w");
  expect_same(ta.rated_torque_nm, tb.rated_torque_nm, "rated_torque_nm");
  expect_same(ta.rated_rotor_speed_rpm, tb.rated_rotor_speed_rpm, "rated_rotor_speed_rpm");
  expect_same(ta.min_rotor_speed_rpm, tb.min_rotor_speed_rpm, "min_rotor_speed_rpm");
  expect_same(ta.cut_in_wind_mps, tb.cut_in_wind_mps, "cut_in");
  expect_same(ta.rated_wind_mps, tb.rated_wind_mps, "rated_wind");
  expect_same(ta.cut_out_wind_mps, tb.cut_out_wind_mps, "cut_out");
  expect_same(ta.rotor_radius_m, tb.rotor_radius_m, "rotor_radius_m");
  expect_same(ta.air_density_kg_m3, tb.air_density_kg_m3, "air_density");
  expect_same(ta.cp_max, tb.cp_max, "cp_max");
  expect_same(ta.lambda_opt, tb.lambda_opt, "lambda_opt");
  expect_same(ta.drivetrain_efficiency, tb.drivetrain_efficiency, "efficiency");
  for (std::size_t i = 0; i < 6; ++i) expect_same(ta.cp.c[i], tb.cp.c[i], "cp.c");
  expect_same(ta.cp.lambda_i_beta, tb.cp.lambda_i_beta, "lambda_i_beta");
  expect_same(ta.cp.lambda_i_cubic, tb.cp.lambda_i_cubic, "lambda_i_cubic");
  expect_same(ta.cp.lambda_scale, tb.cp.lambda_scale, "lambda_scale");
  ASSERT_EQ(a.materials.size(), b.materials.size());
  for (std::size_t i = 0; i < a.materials.size(); ++i) {
    const auto& x = a.materials[i];
    const auto& y = b.materials[i];
    EXPECT_EQ(x.id, y.id);
    for (auto m :
         {&model::Material::youngs_modulus_pa, &model::Material::poisson_ratio,
          &model::Material::density_kg_m3, &model::Material::sigma_hlim_mpa,
          &model::Material::sigma_flim_mpa, &model::Material::sn_contact_m,
          &model::Material::sn_contact_c_mpa, &model::Material::sn_bending_m,
          &model::Material::sn_bending_c_mpa, &model::Material::sn_contact_knee_cycles,
          &model::Material::sn_bending_knee_cycles, &model::Material::reversed_bending_factor}) {
      expect_same(x.*m, y.*m, "material " + x.id);
    }
  }
  ASSERT_EQ(a.shafts.size(), b.shafts.size());
  for (std::size_t i = 0; i < a.shafts.size(); ++i) {
    EXPECT_EQ(a.shafts[i].id, b.shafts[i].id);
    expect_same(a.shafts[i].length_m, b.shafts[i].length_m, "shaft length");
    expect_same(a.shafts[i].diameter_m, b.shafts[i].diameter_m, "shaft diameter");
    EXPECT_EQ(a.shafts[i].material, b.shafts[i].material);
  }
  ASSERT_EQ(a.gears.size(), b.gears.size());
  for (std::size_t i = 0; i < a.gears.size(); ++i) {
    const auto& x = a.gears[i];
    const auto& y = b.gears[i];
    EXPECT_EQ(x.id, y.id);
    EXPECT_EQ(x.shaft, y.shaft);
    EXPECT_EQ(x.teeth, y.teeth);
    expect_same(x.face_width_m, y.face_width_m, "face width " + x.id);
    expect_same(x.mass_kg, y.mass_kg, "mass " + x.id);
    expect_same(x.profile_shift, y.profile_shift, "profile shift " + x.id);
    EXPECT_EQ(x.material, y.material);
  }
  ASSERT_EQ(a.stages.size(), b.stages.size());
  for (std::size_t i = 0; i < a.stages.size(); ++i) {
    const auto& x = a.stages[i];
    const auto& y = b.stages[i];
    EXPECT_EQ(x.id, y.id);
    EXPECT_EQ(x.type, y.type);
    expect_same(x.normal_module_m, y.normal_module_m, "module " + x.id);
    expect_same(x.pressure_angle_rad, y.pressure_angle_rad, "pressure angle " + x.id);
    expect_same(x.helix_angle_rad, y.helix_angle_rad, "helix angle " + x.id);
    EXPECT_EQ(x.planets, y.planets);
    EXPECT_EQ(x.gears, y.gears);
    EXPECT_EQ(x.input_shaft, y.input_shaft);
    EXPECT_EQ(x.output_shaft, y.output_shaft);
  }
  ASSERT_EQ(a.bearings.size(), b.bearings.size());
  for (std::size_t i = 0; i < a.bearings.size(); ++i) {
    const auto& x = a.bearings[i];
    const auto& y = b.bearings[i];
    EXPECT_EQ(x.id, y.id);
    EXPECT_EQ(x.shaft, y.shaft);
    EXPECT_EQ(x.position, y.position);
    EXPECT_EQ(x.elements, y.elements);
    EXPECT_EQ(x.rows, y.rows);
    expect_same(x.element_diameter_m, y.element_diameter_m, "d " + x.id);
    expect_same(x.pitch_diameter_m, y.pitch_diameter_m, "Dp " + x.id);
    expect_same(x.contact_angle_rad, y.contact_angle_rad, "phi " + x.id);
    EXPECT_EQ(x.type, y.type);
    expect_same(x.dynamic_rating_n, y.dynamic_rating_n, "C " + x.id);
    expect_same(x.roller_effective_length_m, y.roller_effective_length_m, "L_we " + x.id);
    expect_same(x.radial_stiffness_n_m, y.radial_stiffness_n_m, "k " + x.id);
  }
  ASSERT_EQ(a.measurement_points.size(), b.measurement_points.size());
  for (std::size_t i = 0; i < a.measurement_points.size(); ++i) {
    EXPECT_EQ(a.measurement_points[i].channel, b.measurement_points[i].channel);
    EXPECT_EQ(a.measurement_points[i].location, b.measurement_points[i].location);
    EXPECT_EQ(a.measurement_points[i].direction, b.measurement_points[i].direction);
  }
  expect_same(a.dynamics.rayleigh_eta, b.dynamics.rayleigh_eta, "eta");
  expect_same(a.dynamics.rayleigh_zeta, b.dynamics.rayleigh_zeta, "zeta");
  for (std::size_t i = 0; i < 3; ++i) {
    expect_same(a.dynamics.mesh_stiffness_scale[i], b.dynamics.mesh_stiffness_scale[i], "mesh k");
    expect_same(a.dynamics.bearing_stiffness_scale[i], b.dynamics.bearing_stiffness_scale[i],
                "bearing k");
  }
  expect_same(a.dynamics.bearing_stiffness_fluctuation, b.dynamics.bearing_stiffness_fluctuation,
              "fluctuation");
  const auto same_array = [&](const auto& x, const auto& y, const char* what) {
    for (std::size_t i = 0; i < x.size(); ++i) expect_same(x[i], y[i], what);
  };
  same_array(a.dynamics.bearing_stiffness_factor, b.dynamics.bearing_stiffness_factor,
             "bearing factor");
  expect_same(a.dynamics.sun_shaft_torsion_scale, b.dynamics.sun_shaft_torsion_scale,
              "sun shaft torsion");
  same_array(a.dynamics.damping_band_factor, b.dynamics.damping_band_factor, "band factor");
  same_array(a.dynamics.transmission_error_m, b.dynamics.transmission_error_m, "TE");
  same_array(a.dynamics.housing_frequency_hz, b.dynamics.housing_frequency_hz, "housing f");
  same_array(a.dynamics.housing_damping_ratio, b.dynamics.housing_damping_ratio, "housing xi");
  same_array(a.dynamics.housing_modal_mass_kg, b.dynamics.housing_modal_mass_kg, "housing m");
  same_array(a.dynamics.housing_participation, b.dynamics.housing_participation, "housing p");
  same_array(a.dynamics.housing_cross_participation, b.dynamics.housing_cross_participation,
             "housing c");
  same_array(a.dynamics.housing_seat_participation, b.dynamics.housing_seat_participation,
             "housing seat c");
}

std::string error_of(const std::string& text, const std::string& source = "bad.toml") {
  try {
    (void)parse_drivetrain(text, source);
  } catch (const DrivetrainFileError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(DrivetrainFile, Paper2mwSurvivesAWriteReadRoundTripInEveryField) {
  // Arrange
  const model::Drivetrain original = model::paper_2mw();
  // Act
  const std::string text = app::config::to_toml(original);
  const model::Drivetrain read = parse_drivetrain(text, "roundtrip.toml");
  // Assert
  expect_equal(read, original);
}

TEST(DrivetrainFile, DefaultAndBuiltinNamesLoadWithoutAFile) {
  const model::Drivetrain d = app::config::load_drivetrain("paper-2mw");
  expect_equal(d, model::paper_2mw());
  const model::Drivetrain k = app::config::load_drivetrain("kelmarsh-mm92");
  EXPECT_EQ(k.name, "kelmarsh-mm92");
  EXPECT_DOUBLE_EQ(k.turbine.rated_power_w, 2.05e6);
  EXPECT_DOUBLE_EQ(k.turbine.rotor_radius_m, 46.0);
}

TEST(DrivetrainFile, BaseIsCopiedAndOnlyTheNamedKeysChange) {
  // Arrange: start from paper-2mw, change one turbine key, one gear key, add a gear (values
  // a real gearbox can have: drivetrain_checks.hpp refuses an impossible one).
  const std::string text = R"(
base = "paper-2mw"
name = "variant"
[turbine]
rated_power_w = 1.8e6
[[gears]]
id = "sun"
mass_kg = 300.0
[[gears]]
id = "extra"
teeth = 40
face_width_m = 0.1
)";
  // Act
  const model::Drivetrain d = parse_drivetrain(text, "variant.toml");
  // Assert
  const model::Drivetrain paper = model::paper_2mw();
  EXPECT_EQ(d.name, "variant");
  EXPECT_DOUBLE_EQ(d.turbine.rated_power_w, 1.8e6);
  EXPECT_DOUBLE_EQ(d.turbine.rated_torque_nm, paper.turbine.rated_torque_nm);
  ASSERT_NE(d.gear("sun"), nullptr);
  EXPECT_DOUBLE_EQ(d.gear("sun")->mass_kg, 300.0);
  EXPECT_EQ(d.gear("sun")->teeth, paper.gear("sun")->teeth);
  EXPECT_DOUBLE_EQ(d.gear("sun")->face_width_m, paper.gear("sun")->face_width_m);
  ASSERT_EQ(d.gears.size(), paper.gears.size() + 1);
  EXPECT_EQ(d.gear("extra")->teeth, 40);
}

TEST(DrivetrainFile, AnglesAreWrittenInDegrees) {
  const model::Drivetrain d = parse_drivetrain(
      "base = \"paper-2mw\"\n[[stages]]\nid = \"planetary\"\npressure_angle_deg = 25\n", "a.toml");
  EXPECT_NEAR(d.stage("planetary")->pressure_angle_rad, 25.0 * 3.14159265358979323846 / 180.0,
              1e-15);
}

TEST(DrivetrainFile, MalformedTomlNamesTheFileAndLine) {
  const std::string e = error_of("name = \"x\"\n[turbine\nrated_power_w = 1\n", "m.toml");
  EXPECT_NE(e.find("m.toml:2:"), std::string::npos) << e;
  EXPECT_NE(e.find("malformed TOML"), std::string::npos) << e;
}

TEST(DrivetrainFile, WrongTypeNamesTheFullKeyAndWhatWasExpected) {
  const std::string e = error_of("base = \"paper-2mw\"\n[turbine]\nrated_power_w = \"lots\"\n");
  EXPECT_NE(e.find("bad.toml:3:"), std::string::npos) << e;
  EXPECT_NE(e.find("key 'turbine.rated_power_w': expected a number > 0, got \"lots\""),
            std::string::npos)
      << e;
}

TEST(DrivetrainFile, OutOfRangeValueIsRejected) {
  const std::string e = error_of("base = \"paper-2mw\"\n[turbine]\nrotor_radius_m = -41\n");
  EXPECT_NE(e.find("key 'turbine.rotor_radius_m': expected a finite number > 0, got -41"),
            std::string::npos)
      << e;
}

TEST(DrivetrainFile, TipReliefIsReadPerStageAndRefusedOutsideZeroToOne) {
  const auto d = app::config::parse_drivetrain(
      "base = \"paper-2mw\"\n[dynamics]\nmesh_tip_relief = [0.5, 0.0, 1.0]\n", "r.toml");
  EXPECT_DOUBLE_EQ(d.dynamics.mesh_tip_relief[0], 0.5);
  EXPECT_DOUBLE_EQ(d.dynamics.mesh_tip_relief[2], 1.0);
  const std::string e =
      error_of("base = \"paper-2mw\"\n[dynamics]\nmesh_tip_relief = [0.5, 1.5, 0.0]\n");
  EXPECT_NE(
      e.find("key 'dynamics.mesh_tip_relief[1]': expected a finite number in [0, 1], got 1.5"),
      std::string::npos)
      << e;
}

TEST(DrivetrainFile, SunShaftTorsionIsReadAndRefusedWhenNotPositive) {
  const auto d = app::config::parse_drivetrain(
      "base = \"paper-2mw\"\n[dynamics]\nsun_shaft_torsion_scale = 2.5\n", "s.toml");
  EXPECT_DOUBLE_EQ(d.dynamics.sun_shaft_torsion_scale, 2.5);
  const std::string e = error_of("base = \"paper-2mw\"\n[dynamics]\nsun_shaft_torsion_scale = 0\n");
  EXPECT_NE(e.find("key 'dynamics.sun_shaft_torsion_scale': expected a finite number > 0"),
            std::string::npos)
      << e;
}

TEST(DrivetrainFile, UnknownKeyIsRejectedWithItsPath) {
  const std::string e = error_of("base = \"paper-2mw\"\n[turbine]\nrated_powr_w = 2e6\n");
  EXPECT_NE(e.find("key 'turbine.rated_powr_w': unknown key"), std::string::npos) << e;
}

TEST(DrivetrainFile, BadListEntryNamesItsIndexAndKey) {
  const std::string e = error_of(
      "base = \"paper-2mw\"\n[[gears]]\nid = \"sun\"\n[[gears]]\nid = \"g9\"\nteeth = 0\n");
  EXPECT_NE(e.find("key 'gears[1].teeth': expected an integer >= 1, got 0"), std::string::npos)
      << e;
}

TEST(DrivetrainFile, ANewEntryMissingARequiredKeyIsRefusedNotWrittenBackAsAnError) {
  // A new gear starts from Gear{}'s defaults: face_width_m = 0 is outside its range, and
  // to_toml() would have written a file the reader refuses (found by fuzz_drivetrain_toml).
  const std::string e =
      error_of("base = \"paper-2mw\"\n[[gears]]\nid = \"g9\"\nteeth = 21\nprofile_shift = 0.2\n");
  EXPECT_NE(e.find("key 'gears[0].face_width_m': missing: a new entry needs it > 0"),
            std::string::npos)
      << e;
}

TEST(DrivetrainFile, ADescriptionWithoutBaseMissingARequiredKeyIsRefusedNotWrittenBackAsAnError) {
  // Without `base`, [turbine] starts from Turbine{}'s defaults like a new list entry:
  // rotor_radius_m = 0 is outside its range, and to_toml() wrote back a file the reader
  // refused (found by fuzz_drivetrain_toml in CI: a [turbine] table cut off after
  // cut_out_wind_mps).
  const std::string e = error_of(
      "name = \"x\"\n[turbine]\nrated_power_w = 2e6\nrated_torque_nm = 1.23e6\n"
      "rated_rotor_speed_rpm = 14.8\nmin_rotor_speed_rpm = 0.0\ncut_in_wind_mps = 4.0\n"
      "rated_wind_mps = 12.0\ncut_out_wind_mps = 20.0\n");
  EXPECT_NE(e.find("key 'turbine.rotor_radius_m': missing: a description without `base` needs "
                   "it > 0"),
            std::string::npos)
      << e;
  // A table the file leaves out entirely is held to the same rule.
  EXPECT_NE(error_of("name = \"x\"\n").find("missing: a description without `base` needs it"),
            std::string::npos);
}

TEST(DrivetrainFile, ControlCharactersInAStringSurviveTheRoundTrip) {
  // TOML forbids raw control characters in a basic string; to_toml() must escape them.
  const model::Drivetrain d =
      parse_drivetrain("base = \"paper-2mw\"\nname = \"a\\nb\\u0001\"\n", "ctl.toml");
  ASSERT_EQ(d.name, std::string("a\nb\x01"));
  const model::Drivetrain again = parse_drivetrain(app::config::to_toml(d), "written.toml");
  EXPECT_EQ(again.name, d.name);
}

TEST(DrivetrainFile, EntryWithoutIdIsRejected) {
  const std::string e = error_of("base = \"paper-2mw\"\n[[bearings]]\nelements = 12\n");
  EXPECT_NE(e.find("key 'bearings[0].id'"), std::string::npos) << e;
}

TEST(DrivetrainFile, BadEnumAndBadArrayAreNamed) {
  std::string e =
      error_of("base = \"paper-2mw\"\n[[stages]]\nid = \"planetary\"\ntype = \"epicyclic\"\n");
  EXPECT_NE(e.find("key 'stages[0].type': expected \"planetary\" or \"parallel\""),
            std::string::npos)
      << e;
  e = error_of("base = \"paper-2mw\"\n[turbine.cp]\nc = [1, 2, 3]\n");
  EXPECT_NE(e.find("key 'turbine.cp.c': expected an array of 6 numbers"), std::string::npos) << e;
}

TEST(DrivetrainFile, UnknownBaseAndInconsistentWindSpeedsAreNamed) {
  std::string e = error_of("base = \"paper-3mw\"\n");
  EXPECT_NE(e.find("key 'base': unknown built-in drivetrain \"paper-3mw\""), std::string::npos)
      << e;
  e = error_of("base = \"paper-2mw\"\n[turbine]\nrated_wind_mps = 25\n");
  EXPECT_NE(e.find("key 'turbine.rated_wind_mps': expected cut_in_wind_mps < rated_wind_mps < "
                   "cut_out_wind_mps"),
            std::string::npos)
      << e;
  e = error_of("base = \"paper-2mw\"\n[[gears]]\nid = \"sun\"\nmaterial = \"unobtainium\"\n");
  EXPECT_NE(e.find("key 'gears[2].material': \"unobtainium\" is not the id of any material"),
            std::string::npos)
      << e;
}

TEST(DrivetrainFile, NeitherBuiltinNorFileIsAClearError) {
  try {
    (void)app::config::load_drivetrain("no-such-drivetrain");
    FAIL() << "accepted";
  } catch (const DrivetrainFileError& e) {
    EXPECT_NE(std::string(e.what()).find("neither a built-in (paper-2mw kelmarsh-mm92"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace

namespace {

TEST(DrivetrainFile, EffectsAreReadByNameAndSurviveARoundTrip) {
  // Arrange: a cracked g4 tooth and a b5 outer-race defect, one parameter left at its default.
  const std::string text =
      "base = \"paper-2mw\"\n"
      "[[effects]]\nkind = \"tooth_crack\"\nlocation = \"g4\"\nstiffness_loss = 0.12\n"
      "[[effects]]\nkind = \"bearing_outer_race_defect\"\nlocation = \"b5\"\n"
      "impact_force_n = 800\nslip = 0.015\n";
  // Act
  const model::Drivetrain d = parse_drivetrain(text, "faulty.toml");
  const model::Drivetrain back = parse_drivetrain(app::config::to_toml(d), "written.toml");
  // Assert
  ASSERT_EQ(d.effects.size(), 2u);
  EXPECT_EQ(d.effects[0].kind, model::EffectKind::kToothCrack);
  EXPECT_EQ(d.effects[0].location, "g4");
  EXPECT_DOUBLE_EQ(*d.effects[0].parameter("stiffness_loss"), 0.12);
  EXPECT_DOUBLE_EQ(*d.effects[1].parameter("defect_width_mm"), 2.0);  // the default
  ASSERT_EQ(back.effects.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(back.effects[i].kind, d.effects[i].kind);
    EXPECT_EQ(back.effects[i].location, d.effects[i].location);
    EXPECT_EQ(back.effects[i].parameters, d.effects[i].parameters);
  }
}

TEST(DrivetrainFile, ABadEffectIsRefusedAtItsEntryAndKey) {
  const std::string head = "base = \"paper-2mw\"\n[[effects]]\n";
  std::string e = error_of(head + "kind = \"cracked_tooth\"\nlocation = \"g4\"\n");
  EXPECT_NE(e.find("effects[0].kind"), std::string::npos) << e;
  EXPECT_NE(e.find("tooth_crack"), std::string::npos) << e;  // lists the ids
  e = error_of(head + "kind = \"tooth_crack\"\nlocation = \"g4\"\ndepth = 0.3\n");
  EXPECT_NE(e.find("'effects[0].depth': unknown parameter of tooth_crack"), std::string::npos) << e;
  e = error_of(head + "kind = \"tooth_crack\"\nlocation = \"g7\"\n");
  EXPECT_NE(e.find("effects[0]"), std::string::npos) << e;
  EXPECT_NE(e.find("location: expected one of"), std::string::npos) << e;
  e = error_of(head + "kind = \"shaft_unbalance\"\nlocation = \"hss\"\nunbalance_kg_m = -1\n");
  EXPECT_NE(e.find("unbalance_kg_m = -1: expected a value in [0, 10]"), std::string::npos) << e;
}

}  // namespace
