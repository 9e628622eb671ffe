#include "fatigue/dynamics_spectrum.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <string>

#include "model/dynamics/simulate.hpp"

namespace app::fatigue {

namespace mf = model::fatigue;

mf::LoadSimulator dynamics_simulator(const model::Drivetrain& drivetrain, const mf::ChannelSet& channels,
                                     const DynamicsSpectrumSettings& settings, std::string* last_error) {
  return [&drivetrain, &channels, settings, last_error](double torque_nm, double rotor_rpm, mf::LoadSeries& out) {
    auto fail = [last_error](std::string what) {
      if (last_error) *last_error = std::move(what);
      return false;
    };
    // Planetary mesh frequency z_ring·f_carrier sets the window length.
    double mesh_hz = 0.0;
    for (const model::GearStage& st : drivetrain.stages) {
      if (st.type != model::StageType::kPlanetary || st.gears.size() != 3) continue;
      if (const model::Gear* ring = drivetrain.gear(st.gears[2])) mesh_hz = ring->teeth * rotor_rpm / 60.0;
    }
    double keep_s = settings.min_seconds;
    if (mesh_hz > 0.0) keep_s = std::max(keep_s, 10.0 / mesh_hz);
    keep_s = std::min(keep_s, settings.max_seconds);
    model::dynamics::SimulationSettings s;
    s.seconds = settings.settle_s + keep_s;
    s.sample_rate_hz = settings.sample_rate_hz;
    s.rom_cutoff_hz = settings.rom_cutoff_hz;
    model::dynamics::SimulationOutputs sim;
    std::string error;
    if (!model::dynamics::simulate_rom(drivetrain, {rotor_rpm, torque_nm}, s, sim, &error)) {
      return fail("dynamics model: " + error);
    }
    if (sim.mesh_force_n.size() != channels.mesh_count()) {
      return fail("dynamics model gives " + std::to_string(sim.mesh_force_n.size()) + " meshes, the fatigue channels expect " +
                  std::to_string(channels.mesh_count()));
    }
    // Bearing slots: ROM index by id, or planet bearing k (−(k+1)).
    std::array<int, mf::kMaxBearings> source{};
    const std::size_t planets = (channels.mesh_count() >= 2) ? (channels.mesh_count() - 2) / 2 : 0;
    for (std::size_t b = 0; b < channels.bearing_count(); ++b) {
      source[b] = -1000;
      for (std::size_t r = 0; r < sim.bearing_ids.size(); ++r) {
        if (sim.bearing_ids[r] == channels.bearing_id(b)) source[b] = static_cast<int>(r);
      }
      if (source[b] == -1000 && channels.bearing(b).shaft == "planet") {
        const std::string& id = channels.bearing_id(b);
        const int k = std::atoi(id.c_str() + channels.bearing(b).id.size()) - 1;
        if (k >= 0 && static_cast<std::size_t>(k) < planets) source[b] = -(k + 1);
      }
      if (source[b] == -1000) return fail("dynamics model has no load for bearing '" + channels.bearing_id(b) + "'");
    }
    std::array<double, mf::kMaxMeshes> to_ft{};
    for (std::size_t m = 0; m < channels.mesh_count(); ++m) {
      const mf::PairGeometry& g = channels.mesh(m).geometry;
      to_ft[m] = std::cos(g.alpha_t_rad) * std::cos(g.beta_b_rad);
    }
    const mf::LoadSample mean = channels.quasi_static_loads(torque_nm);
    const std::size_t n = sim.mesh_force_n.empty() ? 0 : sim.mesh_force_n[0].size();
    const auto skip = static_cast<std::size_t>(settings.settle_s * settings.sample_rate_hz);
    if (n <= skip) return fail("dynamics model returned too few samples");
    // A diverging simulation (e.g. an undamped ROM) must not turn into a damage figure:
    // refuse forces beyond kDivergenceFactor × the quasi-static force at this torque (at
    // least at a tenth of rated torque).
    const double rated = drivetrain.turbine.rated_torque_nm;
    const mf::LoadSample scale = channels.quasi_static_loads(std::max(torque_nm, 0.1 * rated));
    for (std::size_t m = 0; m < channels.mesh_count(); ++m) {
      const double limit = kDivergenceFactor * scale.mesh_force_n[m] / to_ft[m];
      for (std::size_t i = skip; i < n; ++i) {
        const double f = sim.mesh_force_n[m][i];
        if (!std::isfinite(f) || std::abs(f) > limit) {
          return fail("dynamics model diverged at rotor torque " + std::to_string(torque_nm) + " N·m, speed " +
                      std::to_string(rotor_rpm) + " rpm: mesh " + sim.mesh_ids[m] + " force " + std::to_string(f) +
                      " N exceeds " + std::to_string(kDivergenceFactor) +
                      " × its quasi-static value (check the Rayleigh damping of the description)");
        }
      }
    }
    out.dt_s = 1.0 / settings.sample_rate_hz;
    out.samples.resize(n - skip);
    out.rotor_rpm.assign(n - skip, rotor_rpm);
    for (std::size_t i = skip; i < n; ++i) {
      mf::LoadSample& l = out.samples[i - skip];
      for (std::size_t m = 0; m < channels.mesh_count(); ++m) {
        l.mesh_force_n[m] = std::max(0.0, sim.mesh_force_n[m][i]) * to_ft[m];
      }
      for (std::size_t b = 0; b < channels.bearing_count(); ++b) {
        if (source[b] >= 0) {
          const auto r = static_cast<std::size_t>(source[b]);
          l.bearing_radial_n[b] = std::hypot(sim.bearing_force_x_n[r][i], sim.bearing_force_y_n[r][i]);
        } else {
          const auto k = static_cast<std::size_t>(-source[b] - 1);
          l.bearing_radial_n[b] = l.mesh_force_n[k] + l.mesh_force_n[planets + k];
        }
        l.bearing_axial_n[b] = mean.bearing_axial_n[b];
      }
    }
    return true;
  };
}

}  // namespace app::fatigue
