#pragma once
// The drivetrain description: everything the twin knows about one turbine and
// its gearbox, read once at start-up (app/config/ parses the file format) and
// immutable afterwards. The reference turbine of shared/reference/drivetrain-2mw.md
// is built in as `paper-2mw` (paper_2mw.cpp).
//
// Units: SI throughout (m, kg, N, N·m, rad, s) unless the name says otherwise
// (`_rpm`, `_mpa`, `_deg` never appear in stored fields except where noted).
// Thread context: start-up only; the real-time loop reads derived, fixed-size data.

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "model/drivetrain/effects.hpp"

namespace model {

/// Gear material and its fatigue data (ISO 6336-5 / -6).
struct Material {
  std::string id;                    // e.g. "17CrNiMo6"
  double youngs_modulus_pa = 206e9;  // [Pa]
  double poisson_ratio = 0.3;        // [-]
  double density_kg_m3 = 7850.0;     // [kg/m³]
  double sigma_hlim_mpa = 1500.0;    // [MPa] allowable contact stress number, ISO 6336-5
  double sigma_flim_mpa = 500.0;     // [MPa] nominal bending stress number, ISO 6336-5
  // S-N curves N = (C/σ)^m below the knee (ISO 6336-6 / paper eq. for the sun gear).
  double sn_contact_m = 17.035;      // [-]
  double sn_contact_c_mpa = 3090.3;  // [MPa]
  double sn_bending_m = 8.738;       // [-]
  double sn_bending_c_mpa =
      5512.0;  // [MPa] σ_FE = 2·σ_Flim = 1000 MPa at the knee 3e6 (ISO 6336-3 Y_NT)
  double sn_contact_knee_cycles =
      5e7;  // [-] N0, ISO 6336-2 Z_NT knee (case-hardened, some pitting allowed)
  double sn_bending_knee_cycles = 3e6;  // [-] N0, ISO 6336-3 Y_NT knee (case-hardened)
  double reversed_bending_factor =
      0.7;  // [-] Y_M for fully reversed root stress (idler / planet), ISO 6336-3 Annex B
};

/// Knots of a tabulated Cp(λ) curve (CpSurface::table_cp).
inline constexpr std::size_t kCpTableKnots = 12;

/// Power coefficient surface Cp(λ, β): the form is defined in model/wind.
struct CpSurface {
  std::array<double, 6> c{};      // [-] surface coefficients c1..c6 (see model/wind/cp_surface.hpp)
  double lambda_i_beta = 0.08;    // [-] λ_i coupling to pitch
  double lambda_i_cubic = 0.035;  // [-] λ_i pitch cubic term
  double lambda_scale = 1.0;      // [-] s: the surface is evaluated at s·λ (places λ_opt)
  // Optional tabulated Cp(λ, 0) on kCpTableKnots equally spaced λ from table_lambda_min
  // to table_lambda_max (used when max > min; model/wind/cp_surface.hpp).
  double table_lambda_min = 0.0;                 // [-]
  double table_lambda_max = 0.0;                 // [-]
  std::array<double, kCpTableKnots> table_cp{};  // [-] Cp at the knots, each in [0, 16/27]
};

/// What lies between the SCADA measurements and the rotor's aerodynamic power,
/// and between that power and the grid (model/wind/corrections.hpp; fitted to
/// SCADA by `drivetwin fit-cp`). The defaults change nothing.
struct TurbineCorrections {
  double no_load_loss_w = 0.0;           // [W] P_0 in P_el = η·P_aero − P_0
  double nacelle_wind_gain = 1.0;        // [-] a in v_free = a·v_nacelle + b (IEC 61400-12-2 NTF)
  double nacelle_wind_offset_mps = 0.0;  // [m/s] b
  double yaw_loss_exponent = 0.0;        // [-] x in P ∝ cos^x(yaw error); 0: no yaw correction
  // Rotor-effective wind and its spread (model/wind/wind_load.hpp, "With a measured rotor speed").
  double tracking_tip_speed_ratio = 0.0;  // [-] λ_c the controller holds between its speed
                                          // limits; 0: the surface's λ_opt
  double tracking_band_margin = 0.0;      // [-] m: the measured speed gives the wind ωR/λ_c
                                          // between (1 + m)·ω_min and (1 − m)·ω_rated; 0: off
  double turbulence_intensity = 0.0;      // [-] I: the 10-min mean torque is the mean over the
                                          // wind v·(1 + I·ξ), ξ standard normal; 0: at v
};

struct Turbine {
  double rated_power_w = 0.0;          // [W] electrical
  double rated_torque_nm = 0.0;        // [N·m] rotor (gearbox input) torque at rated
  double rated_rotor_speed_rpm = 0.0;  // [rpm]
  double min_rotor_speed_rpm = 0.0;    // [rpm] lowest controlled speed (0: none)
  double cut_in_wind_mps = 0.0;        // [m/s]
  double rated_wind_mps = 0.0;         // [m/s]
  double cut_out_wind_mps = 0.0;       // [m/s]
  double rotor_radius_m = 0.0;         // [m]
  double air_density_kg_m3 = 1.225;    // [kg/m³]
  double cp_max = 0.0;                 // [-] maximum of the Cp surface at β = 0
  double lambda_opt = 0.0;             // [-] tip-speed ratio of cp_max
  CpSurface cp;                        // Cp(λ, β)
  double drivetrain_efficiency = 1.0;  // [-] rotor (aerodynamic) power → electrical power
  double site_altitude_m = 0.0;  // [m] above sea level: pressure for ρ from a measured temperature
  TurbineCorrections corrections;  // SCADA → rotor → grid (defaults: none)
};

enum class StageType { kPlanetary, kParallel };

/// One gear wheel. `id` is a component id (sun, planet, ring, g1..g4 for paper-2mw).
struct Gear {
  std::string id;
  std::string shaft;           // shaft id the gear sits on ("" for the fixed ring, planet pins)
  int teeth = 0;               // [-] z (ring: internal teeth)
  double face_width_m = 0.0;   // [m] b
  double mass_kg = 0.0;        // [kg]
  double profile_shift = 0.0;  // [-] x
  std::string material;        // Material::id
};

/// A gear stage. Planetary: gears = {sun, planet, ring}, carrier = input, ring fixed,
/// sun = output. Parallel: gears = {wheel (input shaft), pinion (output shaft)}.
struct GearStage {
  std::string id;  // "planetary", "intermediate", "high_speed"
  StageType type = StageType::kParallel;
  double normal_module_m = 0.0;     // [m] m_n
  double pressure_angle_rad = 0.0;  // [rad] α_n
  double helix_angle_rad = 0.0;     // [rad] β
  int planets = 0;                  // [-] planetary only
  std::vector<std::string> gears;   // Gear ids, order as above
  std::string input_shaft;          // shaft id driving the stage
  std::string output_shaft;         // shaft id driven by the stage
};

// Shaft::length_m is the modelled length, end to end: the dynamics model (full_model.cpp)
// divides it into equal beam elements and puts the bearings on nodes inside it —
// sun_shaft: sun … b1 … b2 (end), ims: b3 … b4 (the ends), hss: b5 … b6 … generator coupling
// (the lss is not a beam in that model: the carrier is lumped).
struct Shaft {
  std::string id;           // lss, sun_shaft, ims, hss
  double length_m = 0.0;    // [m] modelled length, end to end (above)
  double diameter_m = 0.0;  // [m] mean solid diameter
  std::string material;
};

enum class BearingType { kBall, kRoller };

/// A rolling bearing: geometry fixed by the reference; rating and stiffness are model data.
struct Bearing {
  std::string id;                   // b1..b6, pb
  std::string shaft;                // shaft id ("planet" for the planet bearings)
  std::string position;             // free text, e.g. "rotor side"
  int elements = 0;                 // [-] Nb per row
  int rows = 1;                     // [-]
  double element_diameter_m = 0.0;  // [m] d
  double pitch_diameter_m = 0.0;    // [m] Dp
  double contact_angle_rad = 0.0;   // [rad] φ
  BearingType type = BearingType::kRoller;
  // [N] C, ISO 281 (a catalogue figure; for a pair or two rows, the set's); 0: computed from the
  // geometry above (model/fatigue/bearing_rating.hpp).
  double dynamic_rating_n = 0.0;
  double roller_effective_length_m = 0.0;  // [m] L_we of a roller, for C and C0 from geometry
  // [N] C0, ISO 76 (for the fatigue load limit of the life modification factor); 0: from the
  // geometry (radial roller bearings).
  double static_rating_n = 0.0;
  // [N] C_u, ISO 281:2007 §9.3; 0: from C0 by ISO 281:2007's approximation (bearing_life.hpp).
  double fatigue_load_limit_n = 0.0;
  double radial_stiffness_n_m = 0.0;  // [N/m] mean radial stiffness k_a
};

/// A CMS measurement channel: where the accelerometer sits.
struct MeasurementPoint {
  std::string channel;    // "point1"
  std::string location;   // component id, e.g. "b5"
  std::string direction;  // "radial"
};

/// Stages whose meshes carry a static transmission error (the paper-2mw topology: 3).
inline constexpr std::size_t kTransmissionErrorStages = 3;
/// Harmonics of the mesh frequency in each stage's static transmission error.
inline constexpr std::size_t kTransmissionErrorHarmonics = 3;
/// Measurement points whose bearing seat is modelled with housing modes.
inline constexpr std::size_t kHousingPoints = 2;
/// Housing modes per measurement point (in the sensor's direction).
inline constexpr std::size_t kHousingModesPerPoint = 3;
/// Bearings whose seats can stand in the housing modes: the parallel stages' b3..b6 (the sun
/// shaft's b1, b2 turn with the carrier frame).
inline constexpr std::size_t kHousingSeatBearings = 4;
/// Index of b3 among b1..b6: housing_seat_participation's bearing index is (bearing − b3).
inline constexpr std::size_t kHousingSeatFirstBearing = 2;
/// Knots of the frequency-dependent damping factor (DynamicsParameters::damping_band_factor).
inline constexpr std::size_t kDampingKnots = 3;
/// Frequencies of those knots [Hz]: log-spaced over the band the mesh harmonics of a
/// multi-megawatt gearbox occupy (intermediate mesh ~70 Hz … 3 × hss mesh ~2 kHz).
inline constexpr std::array<double, kDampingKnots> kDampingKnotsHz{100.0, 500.0, 2500.0};

/// Parameters of the dynamics model that are not geometry; the calibrator moves these.
/// Units as named; the physics of each is documented in model/dynamics/full_model.hpp.
struct DynamicsParameters {
  double rayleigh_eta = 0.0;   // [1/s] mass-proportional damping η (C = ηM + ζK)
  double rayleigh_zeta = 0.0;  // [s] stiffness-proportional damping ζ
  std::array<double, 3> mesh_stiffness_scale{1.0, 1.0, 1.0};  // [-] per stage
  /// [-] tip relief per stage, 0 … 1: the fraction of the profile modification that evens the
  /// mesh stiffness out at its design load (model/dynamics/mesh_stiffness.hpp); it smooths
  /// the stiffness variation and so takes the higher mesh harmonics out of its excitation.
  /// 0: unmodified involutes (the model before this parameter).
  std::array<double, 3> mesh_tip_relief{};
  std::array<double, 3> bearing_stiffness_scale{1.0, 1.0, 1.0};  // [-] sun_shaft, ims, hss
  /// [-] scale of each bearing's varying compliance derived from its geometry: its rolling
  /// elements passing through the load zone (model/dynamics/bearing_compliance.hpp; 1: as
  /// derived at zero operating clearance, ~1e-4 of the stiffness for 14–22 rollers; 0: not
  /// derived, the default — measured in session 8 to cost two of five calibrations,
  /// docs/calibration.md).
  double bearing_compliance_scale = 0.0;
  /// [-] k_θ / k_a: an explicit cosine at BPFO, on top of the derived fluctuation (0: none).
  double bearing_stiffness_fluctuation = 0.1;
  /// [-] per bearing b1..b6, on top of its shaft's bearing_stiffness_scale.
  std::array<double, 6> bearing_stiffness_factor{1.0, 1.0, 1.0, 1.0, 1.0, 1.0};
  /// [-] the sun shaft's torsional stiffness against its solid-shaft value G·J/L. The sun
  /// shaft is the quill between the floating sun and the intermediate stage's wheel: its
  /// splines at both ends and its bore make its effective torsional stiffness a factor of
  /// two or more off the mean-diameter figure, and it is the spring of the planetary stage's
  /// torsional mode (the carrier turning against the intermediate shaft, docs/calibration.md).
  double sun_shaft_torsion_scale = 1.0;
  /// [-] multiplies the gearbox's modal damping ratio (Rayleigh's η/2ω + ζω/2) at the
  /// knots kDampingKnotsHz, linear in log frequency between them, constant outside.
  std::array<double, kDampingKnots> damping_band_factor{1.0, 1.0, 1.0};
  /// [m] static transmission error of each stage's meshes: amplitude of harmonic h
  /// (index stage·kTransmissionErrorHarmonics + h − 1) of the mesh frequency, along the
  /// line of action; 0: no geometric excitation (only the stiffness variation).
  std::array<double, kTransmissionErrorStages * kTransmissionErrorHarmonics> transmission_error_m{};
  /// [rad] phase of each of those harmonics against the mesh's tooth-engagement cycle (the
  /// cycle of its stiffness variation): e(τ) = Σ_h a_h cos(2π h τ + φ_h). Where the geometric
  /// error peaks within the engagement is unknown for a real gearbox (profile modifications,
  /// manufacturing), and it decides whether the error adds to or cancels the stiffness
  /// variation's own excitation of that harmonic; 0: in phase (the model before the phases).
  std::array<double, kTransmissionErrorStages * kTransmissionErrorHarmonics>
      transmission_error_phase_rad{};
  /// Housing modes seen at the bearing seat of each measurement point (index
  /// point·kHousingModesPerPoint + mode). A point whose frequencies are all 0 keeps the
  /// model's single seat mass on a spring (StructuralParameters).
  std::array<double, kHousingPoints * kHousingModesPerPoint> housing_frequency_hz{};   // [Hz]
  std::array<double, kHousingPoints * kHousingModesPerPoint> housing_damping_ratio{};  // [-]
  /// [kg] the mode's effective mass at the seat (1/ψ_seat² of a mass-normalised mode)
  std::array<double, kHousingPoints * kHousingModesPerPoint> housing_modal_mass_kg{};
  /// [-] sensor over seat displacement in the mode (ψ_sensor/ψ_seat; 1: sensor on the seat)
  std::array<double, kHousingPoints * kHousingModesPerPoint> housing_participation{};
  /// [-] the mode's participation at the OTHER measured point's seat relative to its own
  /// (housing modes are the whole housing's: cross-transmission between the points; 0: none)
  std::array<double, kHousingPoints * kHousingModesPerPoint> housing_cross_participation{};
  /// [-] the seats of the bearings WITHOUT a measurement point (index
  /// (bearing − b3)·kHousingPoints·kHousingModesPerPoint + point·kHousingModesPerPoint + mode):
  /// each housing mode's participation at that seat relative to its own seat, along the sensor
  /// direction. The seat then moves by Σ c·h_k and its bearing's force drives h_k with c (the
  /// same factor both ways: the coupling is reciprocal and stores no energy of its own).
  /// 0 for every mode (the default): the seat stands on ground, as before this parameter. A
  /// measured bearing's entries must be 0 (its seat is housing_participation's and
  /// housing_cross_participation's).
  std::array<double, kHousingSeatBearings * kHousingPoints * kHousingModesPerPoint>
      housing_seat_participation{};
  /// The gearbox as one body on its supports (torque arms, elastomer mounts): one DOF along
  /// the sensor direction that moves the seat of every parallel-stage bearing b3..b6 and both
  /// sensors alike — the low-frequency path from every bearing to every housing sensor that a
  /// real gearbox has through its rigid-body modes on its mounts. [kg] the body's effective
  /// mass at the seats; 0: no body (every seat on ground or on its housing modes, the model
  /// before these parameters, bit for bit).
  double gearbox_body_mass_kg = 0.0;
  double gearbox_mount_stiffness_n_m = 0.0;  // [N/m] the mounts, body to nacelle frame
  double gearbox_mount_damping_ratio = 0.0;  // [-] the body mode's own ratio (the elastomer's)
};

struct Drivetrain {
  std::string name;
  Turbine turbine;
  std::vector<Material> materials;
  std::vector<Shaft> shafts;
  std::vector<Gear> gears;
  std::vector<GearStage> stages;
  std::vector<Bearing> bearings;
  std::vector<MeasurementPoint> measurement_points;
  DynamicsParameters dynamics;
  // Physics beyond the healthy gearbox (effects.hpp): empty for a healthy drivetrain.
  std::vector<Effect> effects;

  const Gear* gear(std::string_view id) const;
  const Bearing* bearing(std::string_view id) const;
  const Shaft* shaft(std::string_view id) const;
  const Material* material(std::string_view id) const;
  const GearStage* stage(std::string_view id) const;
};

/// The reference 2 MW turbine and gearbox (shared/reference/drivetrain-2mw.md).
Drivetrain paper_2mw();

/// Names of the built-in drivetrains, and lookup by name.
std::vector<std::string> builtin_drivetrain_names();
std::optional<Drivetrain> builtin_drivetrain(std::string_view name);

}  // namespace model
