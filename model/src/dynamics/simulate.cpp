#include "model/dynamics/simulate.hpp"

#include <cmath>

#include "model/drivetrain/kinematics.hpp"
#include "model/dynamics/newmark.hpp"
#include "model/dynamics/rom.hpp"

namespace model::dynamics {
namespace {

bool fail(std::string* error, std::string message) {
  if (error) *error = std::move(message);
  return false;
}

void allocate(std::size_t samples, double rate, SimulationOutputs& out) {
  out.sample_rate_hz = rate;
  out.mesh_force_n.assign(out.mesh_ids.size(), std::vector<double>(samples));
  out.bearing_force_x_n.assign(out.bearing_ids.size(), std::vector<double>(samples));
  out.bearing_force_y_n.assign(out.bearing_ids.size(), std::vector<double>(samples));
  out.acceleration_m_s2.assign(out.sensor_channels.size(), std::vector<double>(samples));
  out.hss_revolutions.assign(samples, 0.0);
}

void prepare(const FullModel& m, std::size_t samples, double rate, SimulationOutputs& out) {
  out = SimulationOutputs{};
  for (const auto& v : m.meshes) out.mesh_ids.push_back(v.id);
  for (const auto& v : m.bearings) out.bearing_ids.push_back(v.id);
  for (const auto& s : m.sensors) out.sensor_channels.push_back(s.channel);
  allocate(samples, rate, out);
}

void prepare(const RomData& d, std::size_t samples, double rate, SimulationOutputs& out) {
  out = SimulationOutputs{};
  for (int j = 0; j < d.mesh_count; ++j) out.mesh_ids.emplace_back(d.mesh_ids[j].view());
  for (int j = 0; j < d.bearing_count; ++j) out.bearing_ids.emplace_back(d.bearing_ids[j].view());
  for (int j = 0; j < d.sensor_count; ++j) out.sensor_channels.emplace_back(d.sensor_ids[j].view());
  allocate(samples, rate, out);
}

}  // namespace

bool check_simulation_inputs(const OperatingPoint& op, const SimulationSettings& s,
                             std::string* error) {
  if (!std::isfinite(op.rotor_speed_rpm) || op.rotor_speed_rpm <= 0.0) {
    return fail(error, "operating point: rotor_speed_rpm must be finite and > 0");
  }
  if (!std::isfinite(op.input_torque_nm) || op.input_torque_nm < 0.0) {
    return fail(error, "operating point: input_torque_nm must be finite and ≥ 0");
  }
  if (!std::isfinite(s.seconds) || s.seconds <= 0.0 || s.seconds > 3600.0) {
    return fail(error, "simulation: seconds must be in (0, 3600]");
  }
  if (!std::isfinite(s.sample_rate_hz) || s.sample_rate_hz <= 0.0) {
    return fail(error, "simulation: sample_rate_hz must be finite and > 0");
  }
  if (s.full_substeps < 1) return fail(error, "simulation: full_substeps must be ≥ 1");
  if (!std::isfinite(s.rom_cutoff_hz) || s.rom_cutoff_hz <= 0.0) {
    return fail(error, "simulation: rom_cutoff_hz must be finite and > 0");
  }
  return true;
}

bool simulate_full(const Drivetrain& d, const OperatingPoint& op, const SimulationSettings& s,
                   SimulationOutputs& out, std::string* error) {
  if (!check_simulation_inputs(op, s, error)) return false;
  const std::optional<FullModel> m = build_full_model(d, s.structure, error);
  if (!m) return false;
  const auto samples = static_cast<std::size_t>(std::llround(s.seconds * s.sample_rate_hz));
  prepare(*m, samples, s.sample_rate_hz, out);
  const double hss_ratio = Kinematics(d).overall_ratio();
  NewmarkIntegrator integ(*m, 1.0 / (s.sample_rate_hz * s.full_substeps));
  integ.reset_static(op);
  for (std::size_t i = 0; i < samples; ++i) {
    for (int k = 0; k < s.full_substeps; ++k) integ.step();
    for (std::size_t j = 0; j < m->meshes.size(); ++j)
      out.mesh_force_n[j][i] = integ.mesh_force_n(j);
    for (std::size_t j = 0; j < m->bearings.size(); ++j) {
      out.bearing_force_x_n[j][i] = integ.bearing_force_n(j, 0);
      out.bearing_force_y_n[j][i] = integ.bearing_force_n(j, 1);
    }
    for (std::size_t j = 0; j < m->sensors.size(); ++j)
      out.acceleration_m_s2[j][i] = integ.sensor_m_s2(j);
    out.hss_revolutions[i] = integ.rotor_revolutions() * hss_ratio;
  }
  return true;
}

bool simulate_rom(const Drivetrain& d, const OperatingPoint& op, const SimulationSettings& s,
                  SimulationOutputs& out, std::string* error) {
  if (!check_simulation_inputs(op, s, error)) return false;
  RomSettings rs;
  rs.dt_s = 1.0 / s.sample_rate_hz;
  rs.cutoff_hz = s.rom_cutoff_hz;
  rs.structure = s.structure;
  const std::unique_ptr<RomData> data = build_rom(d, d.dynamics, rs, error);
  if (!data) return false;
  const auto samples = static_cast<std::size_t>(std::llround(s.seconds * s.sample_rate_hz));
  prepare(*data, samples, s.sample_rate_hz, out);
  const double hss_ratio = Kinematics(d).overall_ratio();
  auto rom = std::make_unique<Rom>(*data);
  const RomInputs in{op.rotor_speed_rpm, op.input_torque_nm};
  rom->reset(in);
  RomOutputs o;
  for (std::size_t i = 0; i < samples; ++i) {
    rom->step(in, o);
    for (int j = 0; j < data->mesh_count; ++j) out.mesh_force_n[j][i] = o.mesh_force_n[j];
    for (int j = 0; j < data->bearing_count; ++j) {
      out.bearing_force_x_n[j][i] = o.bearing_force_x_n[j];
      out.bearing_force_y_n[j][i] = o.bearing_force_y_n[j];
    }
    for (int j = 0; j < data->sensor_count; ++j)
      out.acceleration_m_s2[j][i] = o.acceleration_m_s2[j];
    out.hss_revolutions[i] = rom->rotor_revolutions() * hss_ratio;
  }
  return true;
}

}  // namespace model::dynamics
