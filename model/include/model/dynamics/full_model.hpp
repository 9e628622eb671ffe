#pragma once
// The full-order dynamics model of the drivetrain (paper §2.3.1, VBDM-DT):
//
//  * planetary stage, lumped-parameter (Lin & Parker, J. Vib. Acoust. 121 (1999)):
//    carrier, ring and each planet with x, y, θ; the sun is node 1 of the sun
//    shaft, so the planetary stage couples to the parallel stages there;
//    sun–planet and ring–planet meshes along their lines of action;
//  * the sun shaft (11 elements), intermediate shaft (8) and high-speed shaft (8)
//    as Timoshenko beam elements with four DOF per node (x, y, z, θz): the paper's
//    element has no bending rotations, so each element's lateral stiffness is the
//    Timoshenko beam's with its end slopes held, 12EI / (L³(1+Φ)), Φ = 12EI/(κGAL²)
//    (Cowper's κ for a solid circle); axial EA/L, torsional GJ/L; masses lumped;
//  * helical mesh elements along the normal line of action (α_t, β_b) coupling
//    x, y, z, θ of wheel and pinion; gear masses and inertias lumped at their nodes;
//  * six bearings b1..b6 with k(t) = k_a·(1 + (k_θ/k_a)·cos(2π f_b t + φ_b)) in x and y,
//    f_b the ball-pass frequency of the outer race (model/drivetrain/kinematics.hpp);
//    axial stiffness to the casing (takes the helical axial forces);
//  * the housing under every bearing named by a measurement point (b5 → point1,
//    b3 → point2): in the sensor's direction, the seat moves as the sum of a few
//    housing modes seen from the seat, each a DOF h_k with the mode's effective mass
//    m_k at the seat and stiffness m_k·ω_k² to ground (a modal truncation of the
//    housing: seat displacement Σ h_k, a force F at the seat drives every h_k with F),
//    and the sensor reads Σ p_k·ḧ_k, p_k the mode's sensor-to-seat participation;
//    across it, one seat mass on a support stiffness. A point without housing modes
//    in DynamicsParameters keeps one seat mass on a spring in x and y (its own mode);
//  * the gearbox as a body on its mounts (DynamicsParameters::gearbox_body_mass_kg, 0: none):
//    one DOF u_b along the sensor direction, mass M_b on the mounts' stiffness K_b with
//    their own damping ratio, one more term (participation 1) of the seat displacement of
//    every parallel-stage bearing b3..b6, measured or not, read by both sensors: the
//    rigid-body path from every bearing to every housing sensor. The planetary stage (carrier
//    frame) stays on ground: the body is the parallel-stage end moving on its supports;
//  * static transmission error (the geometric mesh excitation: profile and lead
//    deviations, tip relief): each mesh element's force is k(t)·(δ − e(t)), e a
//    Fourier series in mesh orders per stage (DynamicsParameters::transmission_error_m)
//    at the mesh's own phase (a MeshExcitation of every mesh), so the meshes are excited
//    by the force k(t)·e(t) along their lines of action as well as parametrically by k(t);
//  * damping: modal, C = MΦ·diag(2ξ_iω_i)·ΦᵀM over every mode of the full model, with
//    ξ_i the strain-energy-weighted mix (modal strain energy method, Johnson & Kienholz,
//    AIAA J. 20 (1982)) of the gearbox's ratio — Rayleigh's η/2ω + ζω/2 times a
//    factor piecewise linear in log f (DynamicsParameters::damping_band_factor) — and
//    each housing mode's own ratio, by the share of the mode's strain energy in that
//    housing mode's spring, and of an effect's housing resonance (its own damper) alike. Without
//    housing modes, effects and with unit factors this is exactly C = ηM + ζK̄;
//  * the generator: a rotor inertia on a torsionally flexible coupling at the hss
//    end, held about its nominal speed by the converter (a weak torsional spring).
//
// Coordinates are the vibratory motion about the nominal rotation (the rigid spin
// is removed): the damping therefore damps vibration and does not brake the drivetrain. Gravity is
// not modelled. The input torque acts on the carrier, the reaction on the generator's spring and
// the ring.
//
// The carrier carries the planets round (Lin & Parker 1999 describe the stage in the
// carrier's axes): the carrier, ring, planets and the whole sun shaft (x, y of every node)
// are described in axes turning with the carrier, the intermediate and high-speed shafts,
// the housing seats and the generator in the housing's. In the turning axes every
// planetary mesh, planet bearing, ring and carrier support and every sun-shaft element and
// bearing is constant (they are isotropic about the axis or turn with the carrier), so
// the one element joining the two frames — the intermediate mesh, whose g1 side sees the
// housing-fixed line of action turn backwards at the carrier angle ψ — is the one that
// rotates (VaryingStiffness::rotation_cos/sin). The turning axes add the Coriolis force
// −2Ωm J ẋ and the centripetal +Ω²m x on their translations (Ω the carrier speed,
// ≤ 1.55 rad/s; carrier_frame_xy); the integrator (newmark.hpp) applies them, the reduced
// model neglects them (rom.hpp). docs/dynamics.md gives the derivation and the choice.
//
// Time-varying stiffness is kept apart from the constant mean stiffness K̄, as
// element objects with low-rank directions (a mesh: rank 1 along its line of
// action; a bearing: rank 2, x and y), so that the reduced model reuses them and new
// physics (a cracked tooth's table over one gear revolution, eccentricity forces,
// bearing defect impacts, unbalance, another housing resonance) plugs in as one more
// VaryingStiffness, ForceTerm or DOF without touching the assembly of the others.
//
// Units: SI; rotations in rad, torques in N·m. Thread context: building and
// integrating this model allocates; host/tools/non-RT threads only.

#include <Eigen/Dense>

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "model/drivetrain/description.hpp"
#include "model/dynamics/periodic_table.hpp"

namespace model::dynamics {

/// Mean operating point of the drivetrain.
struct OperatingPoint {
  double rotor_speed_rpm = 0.0;  // [rpm] carrier (rotor) speed
  double input_torque_nm = 0.0;  // [N·m] rotor torque on the carrier
};

/// Structural data the description does not publish: model defaults chosen for a
/// 2 MW three-stage gearbox (documented where each is chosen in full_model.cpp).
struct StructuralParameters {
  double carrier_mass_kg = 3500.0;                  // [kg]
  double carrier_inertia_kg_m2 = 900.0;             // [kg·m²] polar, without the planets
  double carrier_bearing_stiffness_n_m = 5.0e9;     // [N/m] main-shaft bearing, radial
  double ring_support_stiffness_n_m = 5.0e9;        // [N/m] ring to housing, radial
  double ring_torsional_stiffness_nm_rad = 2.0e10;  // [N·m/rad] ring to housing
  double bearing_axial_ratio = 0.3;                 // [-] axial / radial bearing stiffness
  double housing_seat_mass_kg = 250.0;              // [kg] participating housing mass per seat
  double housing_seat_stiffness_n_m = 1.5e10;       // [N/m] seat to the rest of the housing
  double generator_inertia_kg_m2 = 80.0;            // [kg·m²] generator rotor
  double generator_coupling_nm_rad = 5.0e6;         // [N·m/rad] hss ↔ generator coupling
  double generator_control_nm_rad = 2.0e4;          // [N·m/rad] converter speed loop about nominal
  double ims_axis_angle_rad = 0.0;                  // [rad] sun-shaft → ims centre line, from +x
  double hss_axis_angle_rad = 1.5707963267948966;   // [rad] ims → hss centre line, from +x
  double sensor_angle_rad =
      1.5707963267948966;          // [rad] radial sensor direction, from +x (+y: vertical)
  double carrier_angle_rad = 0.0;  // [rad] carrier angle at which the planets are placed
  // The carrier carries the planets round (the carrier frame turns, header comment). false:
  // the planets stay where they were placed (the frame does not turn: frame_order = 0).
  bool carrier_turns = true;
  // Tangential position error of each planet's pin on the carrier [m], + ahead in the
  // carrier's sense of rotation (a manufacturing tolerance; none by default). A pin ahead
  // closes both of its planet's meshes by e·cos α_t: a constant transmission error
  // −e·cos α_t on each (MeshExcitation), so that planet takes more of the torque.
  std::vector<double> planet_pin_error_m;
  // The turning frame's Coriolis and centripetal forces (Newmark). false: left out, as the
  // reduced model leaves them (to measure what that costs: test_fidelity.cpp).
  bool frame_inertia = true;
};

/// A periodic factor of the rotor angle: table(order·N_rotor + phase), N_rotor the rotor
/// revolutions. A cracked tooth's stiffness loss over one revolution of its gear, a
/// centre-distance modulation, a bearing defect's load zone.
struct Modulation {
  PeriodicTable table = PeriodicTable::constant(1.0);  // [-]
  double order = 0.0;                                  // [cycles per rotor revolution]
  double phase_cycles = 0.0;                           // [cycles]
  double value(double rotor_revolutions) const {
    return table.value(order * rotor_revolutions + phase_cycles);
  }
};

/// A displacement excitation of a mesh along its line of action [m]: the no-load
/// transmission error e(t) = amplitude·pattern(N_rotor), positive when the teeth stand
/// apart (the mesh force is k(t)·(δ − e)). An eccentric gear's run-out, a static
/// transmission error over the mesh cycle.
struct MeshExcitation {
  double amplitude_m = 0.0;  // [m]
  Modulation pattern;        // [-]
};

/// A time-varying stiffness: restoring force −k(t)·Σ_c u_c (u_cᵀ x − e(t)),
/// k(t) = mean·shape(order·N_rotor + phase)·Π modulations(N_rotor), e(t) the sum of the
/// excitations (rank-1 elements only; 0 for most).
///
/// Rotation with the carrier frame (full_model.cpp): the planetary stage and the sun shaft
/// are described in axes that turn with the carrier, the rest of the gearbox in the
/// housing's; an element joining the two has directions that turn with the carrier angle
/// ψ = 2π·FullModel::frame_order·N_rotor:
///   u_c(ψ) = directions.col(c) + (cos ψ − 1)·rotation_cos.col(c) + sin ψ·rotation_sin.col(c),
/// so `directions` is the direction at ψ = 0 (rotation_cos/sin empty: a fixed element).
/// The mean stiffness in FullModel::stiffness (K̄) is the one at ψ = 0.
struct VaryingStiffness {
  std::string id;              // "sun_planet_1", "ring_planet_1", "intermediate", "b5", ...
  Eigen::MatrixXd directions;  // [-] or [m/rad] dofs × rank: u_cᵀ x is the element deflection [m]
  double mean_n_m = 0.0;       // [N/m]
  PeriodicTable shape;         // [-] mean 1
  double order = 0.0;          // [cycles per rotor revolution]
  double phase_cycles = 0.0;   // [cycles]
  std::vector<Modulation> modulations;      // [-] multiply k(t) (effects.hpp: a cracked tooth, ...)
  std::vector<MeshExcitation> excitations;  // [m] transmission error along u (rank 1 only)
  Eigen::MatrixXd rotation_cos;             // [-] dofs × rank, or empty (a fixed element)
  Eigen::MatrixXd rotation_sin;             // [-]
  // A rank-2 element (a bearing) whose two columns are x and y of the carrier frame: its
  // forces are turned into the housing frame when reported.
  bool carrier_frame_xy = false;

  double stiffness_n_m(double rotor_revolutions) const {
    double k = mean_n_m * shape.value(order * rotor_revolutions + phase_cycles);
    for (const Modulation& m : modulations) k *= m.value(rotor_revolutions);
    return k;
  }
  double excitation_m(double rotor_revolutions) const {
    double e = 0.0;
    for (const MeshExcitation& x : excitations)
      e += x.amplitude_m * x.pattern.value(rotor_revolutions);
    return e;
  }
  bool rotates() const { return rotation_cos.size() > 0; }
  /// u_c at carrier angle ψ [rad].
  Eigen::VectorXd direction(int c, double psi_rad) const;
};

/// An external force: f(t) = a·shape(order·N_rotor + phase)·Π modulations·
/// (frame[0] + frame[1]·cos ψ + frame[2]·sin ψ)·pattern, with a = amplitude, times the
/// input torque [N·m] when `per_newton_metre`, times the rotor frequency² [Hz²] when
/// `per_rotor_hz_squared` (a rotating unbalance). `frame` turns a force fixed in the
/// housing into the carrier frame's axes (ψ: the carrier angle).
///
/// Impacts with a random spacing (a bearing defect's slip; the truth synthesizer's, not
/// the reduced model's): when `events_revs` is not empty, the shape is read in the local
/// coordinate (N_rotor − event)·order after the latest event instead, 0 past one period.
struct ForceTerm {
  std::string id;           // "input_torque", "b5.outer_race", ...
  Eigen::VectorXd pattern;  // [N or N·m per unit amplitude]
  double amplitude = 1.0;   // [-]
  bool per_newton_metre = false;
  bool per_rotor_hz_squared = false;
  PeriodicTable shape = PeriodicTable::constant(1.0);
  double order = 0.0;         // [cycles per rotor revolution]
  double phase_cycles = 0.0;  // [cycles]
  std::vector<Modulation> modulations;
  std::array<double, 3> frame{1.0, 0.0, 0.0};  // [-]
  std::vector<double> events_revs;             // [rotor revolutions] ascending, or empty
  int impact_group = -1;  // ≥ 0: an impact train; terms of one group share their events

  double scale(double rotor_revolutions, double input_torque_nm, double rotor_hz = 0.0,
               double psi_rad = 0.0) const;
  /// Mean of the amplitude factor over time (shape and modulations averaged
  /// independently; frame terms with cos/sin average to 0): the static part.
  double mean_scale(double input_torque_nm, double rotor_hz = 0.0) const;
};

/// A sensor: acceleration = rowᵀ ẍ [m/s²].
struct Sensor {
  std::string channel;   // "point1"
  std::string location;  // bearing id of the seat, "b5"
  Eigen::VectorXd row;   // [-]
};

/// Centres and contact geometry of a mesh (for checks and reports).
struct MeshInfo {
  Eigen::Vector2d driver_centre_m{0, 0};  // [m] gear A (force on B = +k δ n)
  Eigen::Vector2d driven_centre_m{0, 0};  // [m] gear B
  Eigen::Vector2d pitch_point_m{0, 0};    // [m] pitch point (on the line of centres)
  Eigen::Vector3d normal{0, 0, 0};        // [-] n, unit
  double driven_base_radius_m = 0.0;      // [m] transverse base radius of B
  double stage_torque_ratio = 0.0;        // [-] torque on gear B's shaft per N·m of input torque
  double base_helix_angle_rad = 0.0;      // [rad]
  int planets_sharing = 1;                // [-] meshes sharing that torque
};

struct FullModel {
  std::vector<std::string> dof_names;  // "carrier.x", "sun_shaft.3.theta", "seat.b5.y", ...
  Eigen::VectorXd mass;                // [kg or kg·m²] lumped (diagonal) mass matrix
  Eigen::MatrixXd stiffness;       // [N/m ...] K̄: constant part incl. the varying elements' means
  double rayleigh_eta = 0.0;       // [1/s] (the gearbox's damping before its band factors)
  double rayleigh_zeta = 0.0;      // [s]
  Eigen::MatrixXd damping_matrix;  // [N·s/m ...] C, modal (see the header comment)
  std::vector<double> modal_damping_ratio;  // [-] ξ_i of every mode, ascending frequency
  std::vector<VaryingStiffness> meshes;  // 3 sun–planet, 3 ring–planet, intermediate, high_speed
  std::vector<MeshInfo> mesh_info;       // parallel to `meshes`
  std::vector<VaryingStiffness> bearings;  // b1..b6
  // Other time-varying couplings, treated like the bearings by the reduced model: a
  // planet-pass transmission path (effects.hpp). Usually empty.
  std::vector<VaryingStiffness> paths;
  std::vector<ForceTerm> forces;  // input torque first, then the effects' forces
  std::vector<Sensor> sensors;    // point1, point2
  // Carrier revolutions per rotor revolution (1: the carrier is the rotor shaft).
  double frame_order = 1.0;
  // DOF pairs (x, y) described in the carrier frame: the carrier, ring, planets and the
  // sun shaft's nodes. They carry the Coriolis and centripetal terms of the turning frame.
  std::vector<std::array<int, 2>> carrier_frame_xy;
  bool frame_inertia = true;  // StructuralParameters::frame_inertia

  int dofs() const { return static_cast<int>(mass.size()); }
  /// Index of a named DOF, −1 if absent.
  int dof(std::string_view name) const;
  /// C (damping_matrix).
  const Eigen::MatrixXd& damping() const { return damping_matrix; }
  /// Sum of the external forces at (rotor revolutions, torque, rotor frequency) [N, N·m],
  /// without the meshes' transmission error (mesh_excitation_force()).
  Eigen::VectorXd force(double rotor_revolutions, double input_torque_nm,
                        double rotor_hz = 0.0) const;
  /// Σ u(ψ)·k(t)·e(t) over the meshes with an excitation [N, N·m].
  Eigen::VectorXd mesh_excitation_force(double rotor_revolutions) const;
  /// Carrier angle ψ at a rotor angle [rad].
  double carrier_angle_rad(double rotor_revolutions) const;
  /// The mean stiffness with the turning elements at the carrier angle of
  /// `rotor_revolutions` (K̄ itself at 0).
  Eigen::MatrixXd stiffness_at(double rotor_revolutions) const;
  /// K̄⁻¹ f for the mean (constant) force: the static deflection under the input torque.
  Eigen::VectorXd static_deflection(double input_torque_nm) const;
  /// The same at the carrier angle of `rotor_revolutions` (stiffness_at()).
  Eigen::VectorXd static_deflection_at(double input_torque_nm, double rotor_revolutions) const;
  /// Mean force of mesh i at a static deflection x and rotor angle [N].
  double static_mesh_force(std::size_t i, const Eigen::VectorXd& x,
                           double rotor_revolutions = 0.0) const;
};

/// Gives every impact train of `model` (bearing defects: ForceTerm::impact_group ≥ 0)
/// impact times with a random spacing over `seconds` at a constant rotor frequency
/// `rotor_hz` — each interval the nominal period × (1 + jitter·N(0, 1)), the slip's random
/// part that real bearings show (Randall & Antoni 2011: 1–2 %). The truth synthesizer's
/// (tools/); the reduced model takes the deterministic train (rom.hpp refuses events).
void randomise_impacts(FullModel& model, double jitter, double seconds, double rotor_hz,
                       unsigned long long seed);

/// Builds the model of a drivetrain with one planetary stage (carrier in, ring
/// fixed, sun out) followed by two parallel helical stages (the paper-2mw
/// topology). nullopt, with `error` naming the missing or bad item, otherwise.
std::optional<FullModel> build_full_model(const Drivetrain& drivetrain,
                                          const StructuralParameters& structure = {},
                                          std::string* error = nullptr);

}  // namespace model::dynamics
