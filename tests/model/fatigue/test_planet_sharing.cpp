// Planet load sharing in the quasi-static loads (issue 15, finding 7): with no dynamics to
// say which planet carries more, every planet mesh and planet bearing carries the factor
// K_γ of IEC 61400-4 times its equal share (1.10 for three planets); the hand values below
// come from the tooth counts of drivetrain-2mw.md.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "model/drivetrain/description.hpp"
#include "model/fatigue/drivetrain_channels.hpp"

namespace {

using namespace model::fatigue;

std::size_t sharing_mesh_slot(const ChannelSet& cs, const std::string& id) {
  for (std::size_t i = 0; i < cs.mesh_count(); ++i)
    if (cs.mesh_id(i) == id) return i;
  ADD_FAILURE() << "no mesh " << id;
  return 0;
}
std::size_t bearing_slot(const ChannelSet& cs, const std::string& id) {
  for (std::size_t i = 0; i < cs.bearing_count(); ++i)
    if (cs.bearing_id(i) == id) return i;
  ADD_FAILURE() << "no bearing " << id;
  return 0;
}

TEST(PlanetLoadSharing, TheFactorIsIec614004sForThePlanetCount) {
  EXPECT_DOUBLE_EQ(planet_load_sharing_factor(3), 1.10);
  EXPECT_DOUBLE_EQ(planet_load_sharing_factor(4), 1.25);
  EXPECT_DOUBLE_EQ(planet_load_sharing_factor(5), 1.35);
  EXPECT_DOUBLE_EQ(planet_load_sharing_factor(6), 1.44);
  EXPECT_DOUBLE_EQ(planet_load_sharing_factor(7), 1.47);
  EXPECT_DOUBLE_EQ(planet_load_sharing_factor(1), 1.0);
}

TEST(PlanetLoadSharing, QuasiStaticPlanetMeshesAndBearingsCarryKGammaTimesTheirEqualShare) {
  // Arrange: paper-2mw, T = 1e6 N·m. Ring fixed: T_sun = T·z_s/(z_s + z_r) = T·21/120; the
  // tangential force per planet at the sun's reference circle (d = z·m_n = 21·17 mm) is
  // T_sun/(3·d/2); the planet bearing takes the sun's and the ring's tangential forces, 2·F_t.
  const model::Drivetrain d = model::paper_2mw();
  const ChannelSet cs(d, ChannelOptions{});
  ASSERT_TRUE(cs.valid()) << cs.error();
  const double t = 1.0e6;
  const double f_equal = t * 21.0 / 120.0 / (3.0 * 0.5 * 21 * 0.017);
  // Act
  const LoadSample l = cs.quasi_static_loads(t);
  // Assert
  EXPECT_DOUBLE_EQ(cs.planet_load_sharing(), 1.10);
  for (int k = 1; k <= 3; ++k) {
    const std::string n = std::to_string(k);
    EXPECT_NEAR(l.mesh_force_n[sharing_mesh_slot(cs, "sun-planet" + n)], 1.10 * f_equal,
                1e-6 * f_equal);
    EXPECT_NEAR(l.mesh_force_n[sharing_mesh_slot(cs, "planet" + n + "-ring")], 1.10 * f_equal,
                1e-6 * f_equal);
    EXPECT_NEAR(l.bearing_radial_n[bearing_slot(cs, "pb" + n)], 2.0 * 1.10 * f_equal,
                1e-6 * f_equal);
  }
  // The parallel stages are single paths: no factor (g1 carries T_sun/(d_g1/2) at its
  // transverse reference circle).
  const double d_g1 = 92 * 0.014 / std::cos(10.0 * 3.14159265358979323846 / 180.0);
  EXPECT_NEAR(l.mesh_force_n[sharing_mesh_slot(cs, "g1-g2")], t * 21.0 / 120.0 / (0.5 * d_g1),
              1e-6 * f_equal);
}

TEST(PlanetLoadSharing, AStatedFactorReplacesTheStandards) {
  ChannelOptions o;
  o.planet_load_sharing = 1.0;  // e.g. a gearbox with a measured, even sharing
  const ChannelSet even(model::paper_2mw(), o);
  const ChannelSet standard(model::paper_2mw(), ChannelOptions{});
  const std::size_t s = sharing_mesh_slot(even, "sun-planet1");
  EXPECT_NEAR(standard.quasi_static_loads(1e6).mesh_force_n[s] /
                  even.quasi_static_loads(1e6).mesh_force_n[s],
              1.10, 1e-12);
}

}  // namespace
