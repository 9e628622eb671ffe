#include "cli/sample_rate_check.hpp"

#include <algorithm>
#include <cstdio>

#include "model/drivetrain/kinematics.hpp"

namespace app::cli {

std::string check_sample_rate(const char* option, double rate_hz,
                              const model::Drivetrain& drivetrain, double max_rotor_rpm,
                              double cutoff_hz, const char* cutoff_option,
                              const SampleRateNeeds& needs) {
  const model::Kinematics kin(drivetrain);
  double mesh_hz = 0.0;
  for (std::size_t st = 0; st < kin.stage_count(); ++st)
    mesh_hz = std::max(mesh_hz, kin.mesh_hz(st, max_rotor_rpm));
  const double for_mesh = needs.mesh_factor * mesh_hz;
  const double for_modes = needs.mode_factor * cutoff_hz;
  const double min_rate = std::max(for_mesh, for_modes);
  if (rate_hz >= min_rate) return std::string();
  char text[512];
  std::snprintf(text, sizeof text,
                "%s: %g Hz cannot represent this simulation: the high-speed mesh line at %.1f Hz "
                "(rotor %g rpm) needs >= %.0f Hz (%s) and the ROM's modes up to %.0f Hz%s need "
                ">= %.0f Hz (%gx); expected >= %.0f Hz",
                option, rate_hz, mesh_hz, max_rotor_rpm, for_mesh, needs.mesh_why, cutoff_hz,
                cutoff_option != nullptr && for_modes > for_mesh
                    ? (std::string(" (") + cutoff_option + ")").c_str()
                    : "",
                for_modes, needs.mode_factor, min_rate);
  return text;
}

}  // namespace app::cli
