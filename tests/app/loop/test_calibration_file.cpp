// The running twin's calibrated parameters on disk (app/loop/calibration_worker.hpp):
// every quantity the standard space calibrates survives a save and a load exactly, an old
// file of the paper's 8 changes only those, and a damaged or out-of-range file is refused
// with a message naming the file and what was wrong.
#include <gtest/gtest.h>

#include <boost/crc.hpp>

#include <cinttypes>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "loop/calibration_worker.hpp"
#include "model/drivetrain/description.hpp"
#include "run_test_util.hpp"

namespace {

using run_test::TempDir;

// Every field of DynamicsParameters set to a value no default has, with digits that only a
// shortest-round-trip writer keeps (1/3, 1/7…).
model::DynamicsParameters unusual() {
  model::DynamicsParameters p;
  double v = 1.0;
  auto next = [&v] {
    v += 1.0 / 7.0;
    return v / 3.0;
  };
  p.rayleigh_eta = next();
  p.rayleigh_zeta = next() * 1e-6;
  for (double& x : p.mesh_stiffness_scale) x = next();
  for (double& x : p.mesh_tip_relief) x = next() / 10.0;
  for (double& x : p.bearing_stiffness_scale) x = next();
  p.bearing_stiffness_fluctuation = next() / 10.0;
  for (double& x : p.bearing_stiffness_factor) x = next();
  p.sun_shaft_torsion_scale = next();
  for (double& x : p.damping_band_factor) x = next();
  for (double& x : p.transmission_error_m) x = next() * 1e-6;
  for (double& x : p.transmission_error_phase_rad) x = -next();
  for (double& x : p.housing_frequency_hz) x = 1000.0 * next();
  for (double& x : p.housing_damping_ratio) x = next() / 50.0;
  for (double& x : p.housing_modal_mass_kg) x = 100.0 * next();
  for (double& x : p.housing_participation) x = next();
  for (double& x : p.housing_cross_participation) x = -next() / 5.0;
  for (double& x : p.housing_seat_participation) x = next() / 7.0;
  return p;
}

template <class A>
void expect_same(const A& a, const A& b, const char* what) {
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i], b[i]) << what << "[" << i << "]";
}

void expect_same(const model::DynamicsParameters& a, const model::DynamicsParameters& b) {
  EXPECT_EQ(a.rayleigh_eta, b.rayleigh_eta);
  EXPECT_EQ(a.rayleigh_zeta, b.rayleigh_zeta);
  expect_same(a.mesh_stiffness_scale, b.mesh_stiffness_scale, "mesh_stiffness_scale");
  expect_same(a.mesh_tip_relief, b.mesh_tip_relief, "mesh_tip_relief");
  expect_same(a.bearing_stiffness_scale, b.bearing_stiffness_scale, "bearing_stiffness_scale");
  EXPECT_EQ(a.bearing_stiffness_fluctuation, b.bearing_stiffness_fluctuation);
  expect_same(a.bearing_stiffness_factor, b.bearing_stiffness_factor, "bearing_stiffness_factor");
  EXPECT_EQ(a.sun_shaft_torsion_scale, b.sun_shaft_torsion_scale);
  expect_same(a.damping_band_factor, b.damping_band_factor, "damping_band_factor");
  expect_same(a.transmission_error_m, b.transmission_error_m, "transmission_error_m");
  expect_same(a.transmission_error_phase_rad, b.transmission_error_phase_rad,
              "transmission_error_phase_rad");
  expect_same(a.housing_frequency_hz, b.housing_frequency_hz, "housing_frequency_hz");
  expect_same(a.housing_damping_ratio, b.housing_damping_ratio, "housing_damping_ratio");
  expect_same(a.housing_modal_mass_kg, b.housing_modal_mass_kg, "housing_modal_mass_kg");
  expect_same(a.housing_participation, b.housing_participation, "housing_participation");
  expect_same(a.housing_cross_participation, b.housing_cross_participation,
              "housing_cross_participation");
  expect_same(a.housing_seat_participation, b.housing_seat_participation,
              "housing_seat_participation");
}

std::string read(const std::string& file) {
  std::ifstream in(file);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// A file as the worker writes it: the body, then "crc <CRC-32 of the body>".
void write_with_crc(const std::string& file, const std::string& body) {
  boost::crc_32_type crc;
  crc.process_bytes(body.data(), body.size());
  char tail[32];
  std::snprintf(tail, sizeof tail, "crc %08" PRIx32 "\n", crc.checksum());
  std::ofstream(file) << body << tail;
}

TEST(CalibrationFile, EveryQuantityTheStandardSpaceCalibratesSurvivesASaveAndALoadExactly) {
  // Arrange
  const TempDir dir("calibration-file");
  const std::string file = (dir.path / "calibration.txt").string();
  const model::DynamicsParameters saved = unusual();
  const model::DynamicsParameters base = model::paper_2mw().dynamics;
  // Act
  std::string error;
  ASSERT_TRUE(app::loop::save_calibration(file, saved, 7, &error)) << error;
  std::uint32_t generation = 0;
  const auto loaded = app::loop::load_calibration(file, base, &generation, &error);
  // Assert: nothing of the base shows through, every value is the saved double.
  ASSERT_TRUE(loaded.has_value()) << error;
  EXPECT_EQ(generation, 7u);
  expect_same(*loaded, saved);
}

TEST(CalibrationFile, AFileOfThePapersEightVariablesChangesOnlyThoseOverTheDescription) {
  // Arrange: version 1, as the worker wrote it before the standard space; the description
  // has housing modes and transmission errors the file knows nothing of.
  const TempDir dir("calibration-file");
  const std::string file = (dir.path / "calibration.txt").string();
  model::DynamicsParameters base = unusual();
  write_with_crc(file,
                 "drivetwin-calibration 1\ngeneration 3\nrayleigh_eta 4.5\nrayleigh_zeta 2e-06\n"
                 "mesh_stiffness_scale 1.1 0.9 1.2\nbearing_stiffness_scale 0.8 1.3 1.05\n"
                 "bearing_stiffness_fluctuation 0.07\n");
  // Act
  std::string error;
  std::uint32_t generation = 0;
  const auto loaded = app::loop::load_calibration(file, base, &generation, &error);
  // Assert
  ASSERT_TRUE(loaded.has_value()) << error;
  EXPECT_EQ(generation, 3u);
  model::DynamicsParameters expected = base;
  expected.rayleigh_eta = 4.5;
  expected.rayleigh_zeta = 2e-6;
  expected.mesh_stiffness_scale = {1.1, 0.9, 1.2};
  expected.bearing_stiffness_scale = {0.8, 1.3, 1.05};
  expected.bearing_stiffness_fluctuation = 0.07;
  expect_same(*loaded, expected);
}

TEST(CalibrationFile, AFlippedBitOrAValueOutOfItsRangeIsRefusedWithTheFileAndTheKey) {
  // Arrange
  const TempDir dir("calibration-file");
  const std::string file = (dir.path / "calibration.txt").string();
  std::string error;
  ASSERT_TRUE(app::loop::save_calibration(file, unusual(), 2, &error)) << error;
  std::string text = read(file);
  const std::size_t at = text.find("rayleigh_eta = ") + 15;
  text[at] = static_cast<char>(text[at] ^ 0x01);
  std::ofstream(file) << text;
  // Act
  std::uint32_t generation = 0;
  const auto flipped = app::loop::load_calibration(file, {}, &generation, &error);
  // Assert
  EXPECT_FALSE(flipped.has_value());
  EXPECT_NE(error.find(file), std::string::npos) << error;
  EXPECT_NE(error.find("CRC mismatch"), std::string::npos) << error;

  // Arrange: a well-formed file (its CRC right) whose stiffness scale is negative.
  write_with_crc(file,
                 "# drivetwin-calibration 2\n# generation 4\n[dynamics]\n"
                 "mesh_stiffness_scale = [1.0, -0.5, 1.0]\n");
  // Act
  error.clear();
  const auto negative = app::loop::load_calibration(file, {}, &generation, &error);
  // Assert
  EXPECT_FALSE(negative.has_value());
  EXPECT_NE(error.find(file + ":4"), std::string::npos) << error;
  EXPECT_NE(error.find("dynamics.mesh_stiffness_scale"), std::string::npos) << error;
}

}  // namespace
