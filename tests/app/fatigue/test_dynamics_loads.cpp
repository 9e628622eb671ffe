// Conversion of the dynamics model's ROM outputs into fatigue loads.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "fatigue/dynamics_spectrum.hpp"

namespace {
namespace mf = model::fatigue;
constexpr double kDeg = std::numbers::pi / 180.0;

const std::vector<std::string> kMeshes = {"sun_planet_1",  "sun_planet_2",  "sun_planet_3",
                                          "ring_planet_1", "ring_planet_2", "ring_planet_3",
                                          "intermediate",  "high_speed"};
const std::vector<std::string> kBearings = {"b1", "b2", "b3", "b4", "b5", "b6"};

TEST(RomLoadConverter, TurnsLineOfActionForcesIntoIsoTangentialForcesAndPlanetPinLoads) {
  // Arrange
  const model::Drivetrain d = model::paper_2mw();
  const mf::ChannelSet cs(d, mf::ChannelOptions{});
  const app::fatigue::RomLoadConverter conv(d, cs, kMeshes, kBearings);
  ASSERT_TRUE(conv.valid()) << conv.error();
  std::array<double, 8> f{};
  f.fill(1000.0);
  f[2] = -50.0;  // teeth apart
  std::array<double, 6> fx{3.0, 0, 3.0, 0, 0, 0}, fy{4.0, 0, 4.0, 0, 0, 0};
  mf::LoadSample l;
  // Act
  conv.convert(f.data(), fx.data(), fy.data(), 0.0, l);
  // Assert: spur F_t = F_bn·cos20°; helical F_t = F_bn·cos α_n·cos β = F_bn·cos20°·cos10°
  // (ISO 21771: cos α_t·cos β_b = cos α_n·cos β); a tensile (negative) force loads nothing.
  EXPECT_NEAR(l.mesh_force_n[0], 1000.0 * std::cos(20 * kDeg), 1e-9);
  EXPECT_DOUBLE_EQ(l.mesh_force_n[2], 0.0);
  EXPECT_NEAR(l.mesh_force_n[6], 1000.0 * std::cos(20 * kDeg) * std::cos(10 * kDeg), 1e-9);
  // b1: |(3, 4)| = 5 N; planet bearing 1 carries sun- and ring-mesh tangential forces.
  for (std::size_t b = 0; b < cs.bearing_count(); ++b) {
    if (cs.bearing_id(b) == "b1") {
      EXPECT_DOUBLE_EQ(l.bearing_radial_n[b], 5.0);
    }
    if (cs.bearing_id(b) == "pb1") {
      EXPECT_NEAR(l.bearing_radial_n[b], 2000.0 * std::cos(20 * kDeg), 1e-9);
    }
    if (cs.bearing_id(b) == "pb3") {  // sun mesh apart: only the ring mesh
      EXPECT_NEAR(l.bearing_radial_n[b], 1000.0 * std::cos(20 * kDeg), 1e-9);
    }
  }
}

TEST(RomLoadConverter, RefusesADynamicsModelWithADifferentMeshCount) {
  const model::Drivetrain d = model::paper_2mw();
  const mf::ChannelSet cs(d, mf::ChannelOptions{});
  const std::vector<std::string> fewer(kMeshes.begin(), kMeshes.begin() + 6);
  const app::fatigue::RomLoadConverter conv(d, cs, fewer, kBearings);
  EXPECT_FALSE(conv.valid());
  EXPECT_NE(conv.error().find("6 meshes"), std::string::npos);
}

}  // namespace
