#include "fatigue/dynamics_spectrum.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "model/dynamics/simulate.hpp"

namespace app::fatigue {

namespace mf = model::fatigue;

namespace {
std::vector<std::string> ids_of(const model::dynamics::RomId* ids, int count) {
  std::vector<std::string> out;
  for (int i = 0; i < count; ++i) out.emplace_back(ids[i].view());
  return out;
}
}  // namespace

RomLoadConverter::RomLoadConverter(const model::Drivetrain& drivetrain,
                                   const mf::ChannelSet& channels,
                                   const model::dynamics::RomData& rom)
    : RomLoadConverter(drivetrain, channels, ids_of(rom.mesh_ids.data(), rom.mesh_count),
                       ids_of(rom.bearing_ids.data(), rom.bearing_count)) {}

RomLoadConverter::RomLoadConverter(const model::Drivetrain& drivetrain,
                                   const mf::ChannelSet& channels,
                                   const std::vector<std::string>& rom_mesh_ids,
                                   const std::vector<std::string>& rom_bearing_ids)
    : drivetrain_(&drivetrain), channels_(&channels) {
  if (rom_mesh_ids.size() != channels.mesh_count()) {
    error_ = "dynamics model gives " + std::to_string(rom_mesh_ids.size()) +
             " meshes, the fatigue channels expect " + std::to_string(channels.mesh_count());
    return;
  }
  // Bearing slots: ROM index by id, or planet bearing k (−(k+1)).
  planets_ = channels.mesh_count() >= 2 ? (channels.mesh_count() - 2) / 2 : 0;
  for (std::size_t b = 0; b < channels.bearing_count(); ++b) {
    source_[b] = -1000;
    for (std::size_t r = 0; r < rom_bearing_ids.size(); ++r) {
      if (rom_bearing_ids[r] == channels.bearing_id(b)) source_[b] = static_cast<int>(r);
    }
    if (source_[b] == -1000 && channels.bearing(b).shaft == "planet") {
      const std::string& id = channels.bearing_id(b);
      const int k = std::atoi(id.c_str() + channels.bearing(b).id.size()) - 1;
      if (k >= 0 && static_cast<std::size_t>(k) < planets_) source_[b] = -(k + 1);
    }
    if (source_[b] == -1000) {
      error_ = "dynamics model has no load for bearing '" + channels.bearing_id(b) + "'";
      return;
    }
  }
  for (std::size_t m = 0; m < channels.mesh_count(); ++m) {
    const mf::PairGeometry& g = channels.mesh(m).geometry;
    to_ft_[m] = std::cos(g.alpha_t_rad) * std::cos(g.beta_b_rad);
  }
}

RomLoadConverter::DivergenceLimits RomLoadConverter::divergence_limits(
    double torque_nm) const noexcept {
  const double rated = drivetrain_->turbine.rated_torque_nm;
  const mf::LoadSample scale =
      channels_->quasi_static_loads(std::max(std::abs(torque_nm), 0.1 * rated));
  DivergenceLimits limits;
  for (std::size_t m = 0; m < channels_->mesh_count(); ++m)
    limits.mesh_force_n[m] = kDivergenceFactor * scale.mesh_force_n[m] / to_ft_[m];
  return limits;
}

double RomLoadConverter::divergence_limit_n(std::size_t mesh, double torque_nm) const {
  return divergence_limits(torque_nm).mesh_force_n[mesh];
}

bool RomLoadConverter::within(const DivergenceLimits& limits,
                              const double* mesh_force_n) const noexcept {
  // `!(|f| <= limit)` is true for NaN as well.
  for (std::size_t m = 0; m < channels_->mesh_count(); ++m)
    if (!(std::abs(mesh_force_n[m]) <= limits.mesh_force_n[m])) return false;
  return true;
}

void RomLoadConverter::convert(const double* mesh_force_n, const double* fx, const double* fy,
                               double mean_torque_nm, mf::LoadSample& l) const {
  const mf::ChannelSet& cs = *channels_;
  for (std::size_t m = 0; m < cs.mesh_count(); ++m)
    l.mesh_force_n[m] = std::max(0.0, mesh_force_n[m]) * to_ft_[m];
  const mf::LoadSample mean = cs.quasi_static_loads(mean_torque_nm);
  for (std::size_t b = 0; b < cs.bearing_count(); ++b) {
    if (source_[b] >= 0) {
      const auto r = static_cast<std::size_t>(source_[b]);
      l.bearing_radial_n[b] = std::hypot(fx[r], fy[r]);
    } else {
      const auto k = static_cast<std::size_t>(-source_[b] - 1);
      l.bearing_radial_n[b] = l.mesh_force_n[k] + l.mesh_force_n[planets_ + k];
    }
    l.bearing_axial_n[b] = mean.bearing_axial_n[b];
  }
}

mf::SpectrumGrid dynamics_grid(const model::Drivetrain& d) {
  constexpr std::uint32_t kBelowRated = 12;
  mf::SpectrumGrid g;
  const double rated_rpm =
      d.turbine.rated_rotor_speed_rpm > 0 ? d.turbine.rated_rotor_speed_rpm : 15.0;
  const double step = rated_rpm / kBelowRated;
  g.speed_min_rpm = step;
  g.speed_max_rpm = rated_rpm + 2.0 * step;
  g.speed_points = kBelowRated + 2;
  g.torque_max_nm = 1.5 * d.turbine.rated_torque_nm;
  g.torque_points = 31;
  return g;
}

mf::LoadSimulator dynamics_simulator(const model::Drivetrain& drivetrain,
                                     const mf::ChannelSet& channels,
                                     const DynamicsSpectrumSettings& settings,
                                     std::string* last_error) {
  return [&drivetrain, &channels, settings, last_error](double torque_nm, double rotor_rpm,
                                                        mf::LoadSeries& out) {
    auto fail = [last_error](std::string what) {
      if (last_error) *last_error = std::move(what);
      return false;
    };
    // Planetary mesh frequency z_ring·f_carrier sets the window length.
    double mesh_hz = 0.0;
    for (const model::GearStage& st : drivetrain.stages) {
      if (st.type != model::StageType::kPlanetary || st.gears.size() != 3) continue;
      if (const model::Gear* ring = drivetrain.gear(st.gears[2]))
        mesh_hz = ring->teeth * rotor_rpm / 60.0;
    }
    double keep_s = std::max(settings.min_seconds, 60.0 / rotor_rpm);
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
    const RomLoadConverter conv(drivetrain, channels, sim.mesh_ids, sim.bearing_ids);
    if (!conv.valid()) return fail(conv.error());
    const std::size_t n = sim.mesh_force_n.empty() ? 0 : sim.mesh_force_n[0].size();
    const auto skip = static_cast<std::size_t>(settings.settle_s * settings.sample_rate_hz);
    if (n <= skip) return fail("dynamics model returned too few samples");
    // A diverging simulation (e.g. an undamped ROM) must not turn into a damage figure.
    for (std::size_t m = 0; m < channels.mesh_count(); ++m) {
      const double limit = conv.divergence_limit_n(m, torque_nm);
      for (std::size_t i = skip; i < n; ++i) {
        const double f = sim.mesh_force_n[m][i];
        if (!std::isfinite(f) || std::abs(f) > limit) {
          return fail("dynamics model diverged at rotor torque " + std::to_string(torque_nm) +
                      " N·m, speed " + std::to_string(rotor_rpm) + " rpm: mesh " + sim.mesh_ids[m] +
                      " force " + std::to_string(f) + " N exceeds " +
                      std::to_string(kDivergenceFactor) +
                      " × its quasi-static value (check the Rayleigh damping of the description)");
        }
      }
    }
    out.dt_s = 1.0 / settings.sample_rate_hz;
    out.samples.resize(n - skip);
    out.rotor_rpm.assign(n - skip, rotor_rpm);
    std::array<double, mf::kMaxMeshes> f{};
    std::array<double, mf::kMaxBearings> fx{}, fy{};
    for (std::size_t i = skip; i < n; ++i) {
      for (std::size_t m = 0; m < sim.mesh_force_n.size(); ++m) f[m] = sim.mesh_force_n[m][i];
      for (std::size_t b = 0; b < sim.bearing_ids.size() && b < mf::kMaxBearings; ++b) {
        fx[b] = sim.bearing_force_x_n[b][i];
        fy[b] = sim.bearing_force_y_n[b][i];
      }
      conv.convert(f.data(), fx.data(), fy.data(), torque_nm, out.samples[i - skip]);
    }
    return true;
  };
}

}  // namespace app::fatigue
