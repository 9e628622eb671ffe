#pragma once
// The full models the dynamics tests build from the reference drivetrain (test_rom.cpp,
// test_rom_stability.cpp, test_full_model.cpp, test_fidelity.cpp).
#include <gtest/gtest.h>

#include <string>

#include "model/drivetrain/description.hpp"
#include "model/dynamics/full_model.hpp"
#include "model/dynamics/periodic_table.hpp"

namespace test_support {

inline model::dynamics::FullModel paper_model(const model::Drivetrain& d = model::paper_2mw()) {
  std::string error;
  auto m = model::dynamics::build_full_model(d, {}, &error);
  EXPECT_TRUE(m.has_value()) << error;
  return *m;
}

// Constant mesh, bearing and path stiffness, no transmission error: what remains time-varying
// is the carrier angle, so the free vibration's energy has nothing to be pumped by but ψ.
inline model::Drivetrain quiet_paper() {
  model::Drivetrain d = model::paper_2mw();
  d.dynamics.transmission_error_m.fill(0.0);
  d.dynamics.bearing_stiffness_fluctuation = 0.0;
  d.dynamics.bearing_compliance_scale = 0.0;
  return d;
}
inline model::dynamics::FullModel quiet_model() {
  model::dynamics::FullModel m = paper_model(quiet_paper());
  for (auto& v : m.meshes) v.shape = model::dynamics::PeriodicTable::constant(1.0);
  return m;
}

// The reference drivetrain with the gearbox body on its mounts (mass 0: no body).
inline model::Drivetrain paper_with_body(double mass_kg, double stiffness_n_m,
                                         double damping_ratio) {
  model::Drivetrain d = model::paper_2mw();
  d.dynamics.gearbox_body_mass_kg = mass_kg;
  d.dynamics.gearbox_mount_stiffness_n_m = stiffness_n_m;
  d.dynamics.gearbox_mount_damping_ratio = damping_ratio;
  return d;
}

}  // namespace test_support
