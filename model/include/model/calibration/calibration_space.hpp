#pragma once
// The calibration space (issue 12): which dynamics parameters a calibration may move, each
// with a physical meaning, a prior and bounds.
//
// Every variable is searched in whitened coordinates
//   z = (u − u_prior) / σ_prior,   u = ln(value) for a positive quantity (stiffness, mass,
//                                   frequency, damping, an error amplitude), else the value,
// so that z = 0 is the prior, one unit is one prior standard deviation whatever the
// quantity, and a Gauss–Newton step with the prior term ‖z‖² is regularised toward the
// prior in the same units everywhere. The prior value is the description's own (the
// model's defaults, or a previous calibration written back with `calibrate --update`).
//
// The standard space (standard()), per the physics each parameter stands for:
//   damping      Rayleigh η, ζ                         ln, σ = ln 2, bounds ×/÷ 10
//                band factors at 100 / 500 / 2500 Hz   ln, σ = ln 2, bounds ×/÷ 5
//   stiffness    mesh stiffness scale per stage        ln, σ = 0.25 (ISO 6336 c_γ), ×/÷ 2
//                tip relief per stage (how smooth the  linear, σ = 0.35, 0 … 1 (the fraction
//                stiffness variation is: its higher    of the modification that evens the
//                harmonics)                            stiffness out; unknown for a real box)
//                bearing stiffness b1..b6              ln, σ = ln 2 (preload, clearance), ×/÷ 4
//                varying compliance (the rollers       ln, σ = ln 10, ×/÷ 100 (derived at zero
//                passing the load zone, derived from   operating clearance; a clearance of up
//                each bearing's geometry: a scale)     to ~¾ of the load deflection raises it
//                                                      ~100×; ÷ 100 stands for "none": ending
//                                                      there is not AT BOUND)
//                explicit cosine fluctuation at BPFO   ln, σ = ln 2, ×/÷ 10 (only where the
//                                                      prior has one)
//   excitation   transmission error per stage and harmonic 1..3
//                                                      ln, σ = ln 3 (the accuracy grade is a
//                                                      tolerance, not a measurement), ×/÷ 50
//                                                      (÷ 50 stands for "no error": ending
//                                                      there is not AT BOUND)
//                and its phase against the engagement cycle
//                                                      linear, σ = π/√3 (uniform: unknown),
//                                                      −2π … 2π (periodic: never a real bound)
//   transfer     per housing mode (3 per point): frequency  ln, σ = 0.35, ×/÷ 2
//                damping ratio                         ln, σ = ln 2, 0.005 … 0.2
//                effective mass at the seat            ln, σ = ln 2, ×/÷ 4
//                sensor participation                  ln, σ = 0.5, ×/÷ 4
//                cross participation (other point)     linear, σ = 0.5, −1 … 1
//                participation at each unmeasured      linear, σ = 0.5, −1 … 1 (prior the
//                parallel-stage bearing's seat, one    description's: 0, the seat on ground)
//                per point (its 3 modes tied)          (default_space(d, true): b4, b6 of
//                                                      paper-2mw; only with the seats named)
//                the gearbox body on its mounts (where the prior has one):
//                effective mass at the seats           ln, σ = ln 2, ×/÷ 4
//                mount stiffness                       ln, σ = ln 3, ×/÷ 20 (soft elastomer
//                                                      to hard-mounted; the body mode moves
//                                                      ×/÷ 4.5 with it alone)
//                mount damping ratio                   ln, σ = ln 2, 0.01 … 0.3
// The paper's 8 variables (η, ζ, mesh scale per stage, bearing scale per parallel shaft)
// are paper(); the peers' comparison and the old tests use it.
//
// Thread context: built at start-up; const afterwards, any thread.

#include <array>
#include <cstddef>
#include <cstdint>

#include "model/drivetrain/description.hpp"

namespace model::calibration {

/// Largest calibration space (the standard one has 66 variables on paper-2mw; the gearbox
/// body adds 3, 69; the two unmeasured seats add 4, 70; each with the released sun shaft
/// torsion one more, 71; body and seats together 74 — over this capacity, which the
/// Jacobian's fixed storage sets (trust_region.hpp): standard() then says so, overflow()).
inline constexpr std::size_t kMaxCalibrationVariables = 72;

/// The gearbox body on its mounts (DynamicsParameters::gearbox_body_mass_kg) where a
/// description has none: an engineering estimate for a 2 MW three-stage box in a three-point
/// suspension, not a measurement (the reference leaves the housing open). ~15 t in all; the
/// planetary end held by the main shaft and the torque arms, the parallel stages behind it move
/// on the supports — at their seats about a third of the mass (a uniform body pitching about
/// one end: m_eff = I/L² = m/3), 5 t. The mounts: two torque-arm elastomer bushings of a few
/// 1e8 N/m each in parallel with the main shaft's bending, ~1e9 N/m at the seats (the body
/// alone on them: (1/2π)√(K/M) = 71 Hz; with the shafts and gears it carries, lower).
/// Elastomer loss factor ~0.15: ξ = 0.08. The space's σ (ln 2 on the mass, ln 3 on the
/// stiffness) and bounds (×/÷ 4, ×/÷ 20) say how little of this is known.
inline constexpr double kNominalGearboxBodyMassKg = 5000.0;     // [kg]
inline constexpr double kNominalGearboxMountStiffness = 1.0e9;  // [N/m]
inline constexpr double kNominalGearboxMountDamping = 0.08;     // [-]

/// `p` with the nominal gearbox body above when it has none (mass 0).
inline DynamicsParameters with_nominal_gearbox_body(DynamicsParameters p) {
  if (!(p.gearbox_body_mass_kg > 0.0)) {
    p.gearbox_body_mass_kg = kNominalGearboxBodyMassKg;
    p.gearbox_mount_stiffness_n_m = kNominalGearboxMountStiffness;
    p.gearbox_mount_damping_ratio = kNominalGearboxMountDamping;
  }
  return p;
}

enum class ParameterField : std::uint8_t {
  kRayleighEta,
  kRayleighZeta,
  kDampingBand,             // index: knot
  kMeshScale,               // index: stage
  kMeshTipRelief,           // index: stage
  kBearingFluctuation,      // index: 0
  kBearingShaftScale,       // index: parallel shaft (paper's variables)
  kBearingFactor,           // index: bearing b1..b6
  kTransmissionError,       // index: stage·harmonics + h − 1
  kTransmissionErrorPhase,  // index: as kTransmissionError
  kHousingFrequency,        // index: point·modes + mode
  kHousingDamping,
  kHousingMass,
  kHousingParticipation,
  kHousingCross,
  kHousingSeat,  // index: (bearing − b3)·modes of both points + point·modes (its 3 modes tied)
  kGearboxBodyMass,        // index: 0
  kGearboxMountStiffness,  // index: 0
  kGearboxMountDamping,    // index: 0
  // The derived varying compliance's scale (bearing_compliance.hpp), index 0.
  kBearingComplianceScale,
  // The sun shaft's torsional stiffness scale (DynamicsParameters::sun_shaft_torsion_scale),
  // index 0: never in a space as built, only released after the placement scan
  // (with_sun_shaft_torsion, resonance_placement.hpp).
  kSunShaftTorsion,
};

struct CalibrationVariable {
  ParameterField field = ParameterField::kRayleighEta;
  std::uint8_t index = 0;
  bool logarithmic = true;  // u = ln(value)
  double prior_sd = 1.0;    // [units of u]
  double lower = 0.0;       // [units of the value] bounds
  double upper = 0.0;
  /// The lower bound stands for zero of a quantity whose physical range starts there (an
  /// error amplitude, searched in ln: prior/50 is "no error" to the model): a fit that ends on
  /// it is within the physical range, not pressing against it.
  bool lower_is_zero = false;
  std::array<char, 40> name{};  // e.g. "housing.point1.mode2.frequency_hz"
  std::array<char, 8> unit{};   // e.g. "Hz", "m", "-"
};

class CalibrationSpace {
 public:
  /// The paper's 8 variables around `prior` (η, ζ, mesh scale per stage, bearing scale per
  /// parallel shaft), bounds as the first calibrator had them (η 0.5–50 1/s, ζ 1e-6–1e-4 s,
  /// scales 0.5–2), prior σ = ln 2 (damping) and 0.25 (scales).
  static CalibrationSpace paper(const DynamicsParameters& prior);
  /// The standard space (header) around `prior`. Housing variables only where the prior
  /// has housing modes (frequency > 0); the seat participations only of the parallel-stage
  /// bearings b3..b6 marked in `unmeasured_seats` (their seats are in the housing but carry
  /// no sensor: DynamicsParameters::housing_seat_participation).
  static CalibrationSpace standard(
      const DynamicsParameters& prior,
      const std::array<bool, kHousingSeatBearings>& unmeasured_seats = {});

  CalibrationSpace() = default;

  /// This space with the sun shaft's torsional stiffness scale added as a variable, centred on
  /// the prior's value: ln, σ = ln 3, bounds ×/÷ 9 (the reference fixes no shaft dimension: bore
  /// and splines put the effective d⁴/L ~×/÷ 3 off; the bounds are the placement scan's range,
  /// kPlacementRange). Not in the standard space: fitted locally from the prior it does not move
  /// the planetary torsional mode toward the recording's (the residual is not monotonic in it:
  /// docs/calibration.md, Session 14); it is released only for the refit that starts where the
  /// placement scan put it. A space already holding it, or full, is returned unchanged but for
  /// overflow().
  CalibrationSpace with_sun_shaft_torsion() const;

  std::size_t size() const { return count_; }
  /// Variables the space was asked for beyond kMaxCalibrationVariables (left out: a caller
  /// must refuse a space with overflow() > 0 rather than calibrate a truncated one).
  std::size_t overflow() const { return overflow_; }
  const CalibrationVariable& variable(std::size_t i) const { return vars_[i]; }
  const char* name(std::size_t i) const { return vars_[i].name.data(); }
  const DynamicsParameters& prior() const { return prior_; }

  /// Bounds of variable i in whitened units.
  double lower(std::size_t i) const;
  double upper(std::size_t i) const;

  /// The value of variable i in parameters p, and setting it.
  static double get(const DynamicsParameters& p, const CalibrationVariable& v);
  static void set(DynamicsParameters& p, const CalibrationVariable& v, double value);

  /// Whitened z (size()) → parameters: the prior's, with every variable set from z.
  DynamicsParameters to_parameters(const double* z) const;
  /// Variables in `base` instead of the prior for the fields not in the space.
  DynamicsParameters to_parameters(const double* z, const DynamicsParameters& base) const;
  /// Parameters → whitened z (clamped into the bounds).
  void to_variables(const DynamicsParameters& p, double* z) const;
  /// Value of variable i at whitened z_i.
  double value(std::size_t i, double z) const;
  /// Whitened z of value v for variable i (unclamped).
  double whiten(std::size_t i, double v) const;

 private:
  void add(ParameterField f, std::size_t index, bool logarithmic, double sd, double lower,
           double upper, const char* name, const char* unit);
  DynamicsParameters prior_{};
  std::array<CalibrationVariable, kMaxCalibrationVariables> vars_{};
  std::array<double, kMaxCalibrationVariables> prior_u_{};
  std::size_t count_ = 0;
  std::size_t overflow_ = 0;
};

}  // namespace model::calibration
