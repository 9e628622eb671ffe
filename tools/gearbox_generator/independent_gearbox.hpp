#pragma once
// An independent generator of gearbox vibration recordings for the calibration tests
// (issue 12): a lumped torsional–lateral model of the reference gearbox (paper-2mw,
// shared/reference/drivetrain-2mw.md) written from the physics WITHOUT the project's
// model code — its own elements, its own structure, its own choice of everything the
// reference leaves open, drawn per seed — so that a calibration that fits it fits a
// gearbox the twin did not simulate.
//
// Degrees of freedom (49, vibration about the nominal rotation, SI, x/y in the housing
// frame, rotations counter-clockwise positive):
//   rotor θ (on the main shaft's torsional spring to the carrier), carrier θ, three
//   planets x, y, θ (on their pins: bearing springs to the carrier, the pins following
//   the carrier's nominal rotation), sun x, y, θ and g1 x, y, θ on the sun shaft with
//   two bearing nodes (b1 between them, b2 beyond g1), the intermediate shaft's nodes
//   b3, g2, g3, b4, the high-speed shaft's nodes b5, g4, b6, the generator θ (on a
//   coupling, held about its nominal angle by the converter's speed loop), and the
//   housing: under b5 and b3 a seat on a wall mass on the housing body (a two-mass chain
//   per direction), the body itself on its mounts; b4 and b6 sit on the body, b1, b2 and
//   the ring on ground. Lateral shaft bending: springs between neighbouring nodes.
// Meshes: along the transverse line of action of the loaded flanks (the driver's
// surface velocity, tilted by the transverse pressure angle away from the driver), force
// k(φ)·(δ − e(φ)) + c·δ̇, φ the mesh phase from the nominal angles: k a single/double
// contact step for the spur planetary stage, a small ripple for the helical stages; e a
// transmission error of up to five harmonics with random phases. Planet i's meshes lag
// by z·ψ_i/2π cycles; the planets' positions turn with the carrier.
// Inputs: rotor speed drifting by up to ±1 % (two slow sinusoids), aerodynamic torque
// with turbulence (an Ornstein–Uhlenbeck process, a few % of the mean) and a 3P ripple.
// Outputs: point1 (b5 seat), point2 (b3 seat) radial accelerations through a sensor of
// gain 1 ± 5 % and a tilt of a few degrees, white noise of a few % of each channel's
// RMS, a once-per-revolution tacho on the hss (5 V, 5 % duty). Integration: classical
// Runge–Kutta at twice the output rate, every second state written.
//
// Extending it (fault effects for issue 14's "second, simpler generator"): an Effect
// adds forces on named DOFs and may scale a mesh's stiffness or add to its
// transmission error as a function of the nominal angles; the residual unbalance of the
// healthy hss (balance grade G 2.5) is implemented that way.
//
// Host tool: allocates, throws std::runtime_error on bad settings.

#include <array>
#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace tools::generator {

/// Nominal angles at one instant [revolutions of each part since t = 0].
struct Angles {
  double time_s = 0.0;
  double carrier = 0.0;  // = rotor
  double sun_shaft = 0.0;
  double ims = 0.0;
  double hss = 0.0;
  double rotor_hz = 0.0;  // [Hz] rotor speed at this instant
};

/// What an effect may change. DOF indices come from IndependentGearbox::dof().
class Effect {
 public:
  virtual ~Effect() = default;
  /// Multiplies mesh m's stiffness (meshes: sun_planet_1..3, ring_planet_1..3, intermediate,
  /// high_speed). Default 1.
  virtual double mesh_stiffness_factor(int /*mesh*/, const Angles& /*a*/) const { return 1.0; }
  /// Adds to mesh m's transmission error [m]. Default 0.
  virtual double mesh_error_m(int /*mesh*/, const Angles& /*a*/) const { return 0.0; }
  /// Adds external forces [N or N·m] to f (one entry per DOF).
  virtual void add_forces(const Angles& /*a*/, std::vector<double>& /*f*/) const {}
};

/// The choices the reference leaves open, one set per seed (draw()).
struct GearboxChoices {
  // Inertia and mass not published.
  double rotor_inertia_kg_m2 = 0;  // rotor + hub
  double carrier_inertia_kg_m2 = 0;
  double generator_inertia_kg_m2 = 0;
  double shaft_node_mass_kg = 0;  // each bearing node's share of its shaft
  // Stiffness.
  double main_shaft_nm_rad = 0;  // rotor ↔ carrier
  double sun_shaft_torsion_nm_rad = 0, ims_torsion_nm_rad = 0;
  double coupling_nm_rad = 0;   // hss ↔ generator
  double converter_nm_rad = 0;  // generator speed loop (proportional)
  double converter_damping_nms_rad = 0;
  double bending_n_m = 0;               // lateral spring between neighbouring shaft nodes
  std::array<double, 7> bearing_n_m{};  // b1..b6, planet bearing
  double bearing_damping_ratio = 0;
  std::array<double, 3> mesh_stiffness_n_m{};  // planetary (each mesh), intermediate, high-speed
  std::array<double, 3> mesh_damping_ratio{};
  double spur_double_single_ratio = 0;  // planetary: double / single contact stiffness
  double helical_ripple = 0;            // relative ripple of the helical stages
  // Transmission error [m], stage × harmonic 1..5, and phases [rad].
  std::array<std::array<double, 5>, 3> te_m{};
  std::array<std::array<double, 5>, 3> te_phase{};
  // Housing: per measured point (0: b5 / point1, 1: b3 / point2).
  std::array<double, 2> seat_mass_kg{}, wall_mass_kg{};
  std::array<double, 2> seat_n_m{}, wall_n_m{};
  double body_mass_kg = 0, body_n_m = 0;
  double housing_damping_ratio = 0;
  double mass_damping_1_s = 0;  // α·M on every DOF
  // Sensors.
  std::array<double, 2> sensor_gain{}, sensor_tilt_rad{};
  double noise_relative = 0;
  // Inputs.
  double turbulence_relative = 0;  // RMS of the torque fluctuation / mean
  double turbulence_corner_hz = 0;
  double ripple_3p_relative = 0;
  double drift_relative = 0;  // peak speed drift
  std::array<double, 2> drift_period_s{}, drift_phase{};
  double hss_unbalance_kg_m = 0;  // residual (G 2.5)

  /// Draws every choice from its documented range (independent_gearbox.cpp).
  static GearboxChoices draw(std::uint64_t seed);
  /// One line per choice, for the bundle's notes and docs.
  std::string describe() const;
};

struct GeneratorSettings {
  double rotor_speed_rpm = 8.33;
  double input_torque_nm = 361747.0;
  double duration_s = 30.0;
  double sample_rate_hz = 25600.0;
  double settle_s = 1.0;  // simulated and discarded before the recording
  std::uint64_t noise_seed = 1;
};

struct GeneratedRecording {
  double sample_rate_hz = 0;
  std::vector<double> point1, point2;  // [m/s²] as the sensors deliver them (gain, tilt, noise)
  std::vector<double> tacho;           // [V]
  double mean_rotor_speed_rpm = 0;     // over the recording
  double mean_input_torque_nm = 0;
};

class IndependentGearbox {
 public:
  explicit IndependentGearbox(const GearboxChoices& choices);
  ~IndependentGearbox();
  IndependentGearbox(const IndependentGearbox&) = delete;
  IndependentGearbox& operator=(const IndependentGearbox&) = delete;

  /// Index of a named DOF ("rotor.theta", "hss.b5.x", "seat.b5.y", ...); −1 if absent.
  int dof(const std::string& name) const;
  int dofs() const;
  /// Effects act from the next run() on (the generator keeps them alive).
  void add_effect(std::shared_ptr<const Effect> effect);

  /// Static mesh forces [N] along the lines of action under the mean torque (for checks):
  /// sun_planet_1..3, ring_planet_1..3, intermediate, high_speed.
  std::vector<double> static_mesh_forces(double input_torque_nm) const;
  /// Transverse base radius of each mesh's driven gear [m] and its torque ratio to the input.
  std::vector<double> driven_base_radius_m() const;
  std::vector<double> driven_torque_ratio() const;

  GeneratedRecording run(const GeneratorSettings& s) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tools::generator
