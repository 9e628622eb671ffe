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
//  * static transmission error (the geometric mesh excitation: profile and lead
//    deviations, tip relief): each mesh element's force is k(t)·(δ − e(t)), e a
//    Fourier series in mesh orders per stage (DynamicsParameters::transmission_error_m)
//    at the mesh's own phase, so the meshes are excited by the force k(t)·e(t) along
//    their lines of action as well as parametrically by k(t);
//  * damping: modal, C = MΦ·diag(2ξ_iω_i)·ΦᵀM over every mode of the full model, with
//    ξ_i the strain-energy-weighted mix (modal strain energy method, Johnson & Kienholz,
//    AIAA J. 20 (1982)) of the gearbox's ratio — Rayleigh's η/2ω + ζω/2 times a
//    factor piecewise linear in log f (DynamicsParameters::damping_band_factor) — and
//    each housing mode's own ratio, by the share of the mode's strain energy in that
//    housing mode's spring. Without housing modes and with unit factors this is exactly
//    C = ηM + ζK̄;
//  * the generator: a rotor inertia on a torsionally flexible coupling at the hss
//    end, held about its nominal speed by the converter (a weak torsional spring).
//
// Coordinates are the vibratory motion about the nominal rotation (the rigid spin
// is removed; gyroscopic and centrifugal terms are neglected, the carrier turns at
// ≤ 0.25 Hz): the damping therefore damps vibration and does not brake the drivetrain. The planets'
// positions are those at t = 0 (the slow carrier rotation is not followed geometrically). Gravity
// is not modelled. The input torque acts on the carrier, the reaction on the generator's spring and
// the ring.
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
      1.5707963267948966;  // [rad] radial sensor direction, from +x (+y: vertical)
};

/// A time-varying stiffness: restoring force −k(t)·Σ_c u_c (u_cᵀ x),
/// k(t) = mean·shape(order·N_rotor(t) + phase), N_rotor the rotor revolutions.
struct VaryingStiffness {
  std::string id;              // "sun_planet_1", "ring_planet_1", "intermediate", "b5", ...
  Eigen::MatrixXd directions;  // [-] or [m/rad] dofs × rank: u_cᵀ x is the element deflection [m]
  double mean_n_m = 0.0;       // [N/m]
  PeriodicTable shape;         // [-] mean 1
  double order = 0.0;          // [cycles per rotor revolution]
  double phase_cycles = 0.0;   // [cycles]
  /// [m] static transmission error e over the same cycle (meshes; 0 for bearings): the
  /// element's force is k(t)·(uᵀx − e(t)).
  PeriodicTable transmission_error = PeriodicTable::constant(0.0);
  double stiffness_n_m(double rotor_revolutions) const {
    return mean_n_m * shape.value(order * rotor_revolutions + phase_cycles);
  }
  double transmission_error_m(double rotor_revolutions) const {
    return transmission_error.value(order * rotor_revolutions + phase_cycles);
  }
};

/// An external force: f(t) = amplitude·shape(order·N_rotor + phase)·pattern, the
/// amplitude multiplied by the input torque [N·m] when `per_newton_metre`.
struct ForceTerm {
  std::string id;           // "input_torque", ...
  Eigen::VectorXd pattern;  // [N or N·m per unit amplitude]
  double amplitude = 1.0;   // [-]
  bool per_newton_metre = false;
  PeriodicTable shape = PeriodicTable::constant(1.0);
  double order = 0.0;         // [cycles per rotor revolution]
  double phase_cycles = 0.0;  // [cycles]
  double scale(double rotor_revolutions, double input_torque_nm) const {
    const double a = per_newton_metre ? amplitude * input_torque_nm : amplitude;
    return a * shape.value(order * rotor_revolutions + phase_cycles);
  }
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
  std::vector<ForceTerm> forces;           // input torque first
  std::vector<Sensor> sensors;             // point1, point2

  int dofs() const { return static_cast<int>(mass.size()); }
  /// Index of a named DOF, −1 if absent.
  int dof(std::string_view name) const;
  /// C (damping_matrix).
  const Eigen::MatrixXd& damping() const { return damping_matrix; }
  /// Sum of the external forces at (rotor revolutions, torque) [N, N·m].
  Eigen::VectorXd force(double rotor_revolutions, double input_torque_nm) const;
  /// The meshes' transmission-error forces Σ k(t)·e(t)·u at the rotor angle [N, N·m].
  Eigen::VectorXd transmission_error_force(double rotor_revolutions) const;
  /// K̄⁻¹ f for the mean (constant) force: the static deflection under the input torque.
  Eigen::VectorXd static_deflection(double input_torque_nm) const;
};

/// Builds the model of a drivetrain with one planetary stage (carrier in, ring
/// fixed, sun out) followed by two parallel helical stages (the paper-2mw
/// topology). nullopt, with `error` naming the missing or bad item, otherwise.
std::optional<FullModel> build_full_model(const Drivetrain& drivetrain,
                                          const StructuralParameters& structure = {},
                                          std::string* error = nullptr);

}  // namespace model::dynamics
