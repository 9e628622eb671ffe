#pragma once
// The entry point other parts of the twin use: operating point → simulated
// CMS waveforms (point1, point2), dynamic mesh forces and bearing loads.
//
//   model::Drivetrain d = model::paper_2mw();            // or a calibrated copy
//   d.dynamics.rayleigh_zeta = 1.2e-5;                   // calibrator's parameters
//   model::dynamics::SimulationOutputs out;
//   std::string error;
//   if (!model::dynamics::simulate_rom(d, {8.33, 361747.0}, {2.0, 25600.0}, out, &error)) ...
//
// simulate_rom() runs the reduced-order model (model/dynamics/rom.hpp, the one the
// box runs); simulate_full() the full-order reference (full_model.hpp, Newmark).
// Both start from the static deflection under the mean stiffness and the input
// torque, at rotor angle 0, and hold speed and torque constant.
//
// Thread context: allocate (outputs, model building); host, tools and non-RT
// threads (calibration, fatigue). Never on the real-time thread.

#include <string>
#include <vector>

#include "model/drivetrain/description.hpp"
#include "model/dynamics/full_model.hpp"

namespace model::dynamics {

struct SimulationSettings {
  double seconds = 2.0;           // [s] simulated time
  double sample_rate_hz = 25600;  // [Hz] output rate; the ROM steps at this rate
  int full_substeps = 2;          // full model: Newmark steps per output sample
  double rom_cutoff_hz =
      2200.0;  // [Hz] ROM: keep every mode up to here (+ static correction); rom.hpp
  StructuralParameters structure{};  // the full model's structural parameters (both models)
};

/// Time series, one value per output sample (sample i at t = (i+1)/sample_rate_hz).
struct SimulationOutputs {
  double sample_rate_hz = 0.0;        // [Hz]
  std::vector<std::string> mesh_ids;  // sun_planet_1..3, ring_planet_1..3, intermediate, high_speed
  std::vector<std::vector<double>>
      mesh_force_n;  // [mesh][sample] [N] along the line of action, compression > 0
  std::vector<std::string> bearing_ids;                // b1..b6
  std::vector<std::vector<double>> bearing_force_x_n;  // [bearing][sample] [N] (see below)
  std::vector<std::vector<double>> bearing_force_y_n;  // [bearing][sample] [N]
  std::vector<std::string> sensor_channels;            // point1, point2
  std::vector<std::vector<double>>
      acceleration_m_s2;                // [sensor][sample] [m/s²] radial seat acceleration
  std::vector<double> hss_revolutions;  // [sample] nominal hss angle / 2π (for a tacho)
};
// Bearing forces are k(t)·(shaft − seat) deflection: the force the shaft exerts on
// the bearing (and the housing), in the housing frame's x and y.

/// Reduced-order model. false with `error` set on bad parameters or inputs.
bool simulate_rom(const Drivetrain& drivetrain, const OperatingPoint& op,
                  const SimulationSettings& settings, SimulationOutputs& out,
                  std::string* error = nullptr);

/// Full-order reference model (Newmark average acceleration, `full_substeps` per sample).
bool simulate_full(const Drivetrain& drivetrain, const OperatingPoint& op,
                   const SimulationSettings& settings, SimulationOutputs& out,
                   std::string* error = nullptr);

/// Checks an operating point and settings: finite, speed > 0, torque ≥ 0, seconds > 0,
/// sample rate > 0. false with `error` naming the field.
bool check_simulation_inputs(const OperatingPoint& op, const SimulationSettings& settings,
                             std::string* error);

}  // namespace model::dynamics
