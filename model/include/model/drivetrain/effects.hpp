#pragma once
// Physics a drivetrain model may leave out (shared/reference/diagnosis-report.md, "Effects
// the model may have left out"): a cracked tooth, an eccentric gear, bearing defects,
// unbalance, misalignment, planet-pass modulation and a housing resonance. An Effect names
// one of them, where it sits and its physical parameters; Drivetrain::effects lists the
// ones a model carries. The dynamics model (model/dynamics/full_model.hpp) turns each into
// a term of its equations of motion, and the reduced model inherits it (rom.hpp).
//
// Who sets them: the drivetrain description file (`[[effect]]` tables, app/config), the
// truth synthesizer (tools/truth), the diagnosis (model/diagnosis) when it tries a
// hypothesis, and the calibrator when it fits one: every effect's parameters are a small
// vector of named, bounded reals (effect_parameters()) that a fit can vary.
//
// Thread context: description data, built off the real-time thread; immutable there.

#include <array>
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace model {

struct Drivetrain;

enum class EffectKind {
  kToothCrack,
  kGearEccentricity,
  kBearingOuterRaceDefect,
  kBearingInnerRaceDefect,
  kBearingBallDefect,
  kShaftUnbalance,
  kShaftMisalignment,
  kPlanetPassModulation,
  kHousingResonance,
};
inline constexpr std::size_t kEffectKinds = 9;
inline constexpr std::size_t kMaxEffectParameters = 4;

/// One parameter of an effect: its name (the key in a description file and in a
/// diagnosis report's "parameters"), unit, default, the range a description may give it,
/// and whether a fit varies it (the others fix the effect's form, e.g. a phase).
struct EffectParameter {
  const char* name;
  const char* unit;
  double default_value;
  double lower;  // inclusive
  double upper;  // inclusive
  bool fitted;
};

/// An effect at one location with its parameters (in the order of effect_parameters()).
struct Effect {
  EffectKind kind = EffectKind::kToothCrack;
  std::string location;  // component id: "g4", "sun", "planet2", "b5", "pb", "hss", "ring", ...
  std::array<double, kMaxEffectParameters> parameters{};

  /// Value of the parameter `name`; nullopt if the kind has no such parameter.
  std::optional<double> parameter(std::string_view name) const;
  /// Sets the parameter `name`; false if the kind has no such parameter.
  bool set_parameter(std::string_view name, double value);
};

/// The contract's id ("tooth_crack", ...) and back (nullopt for an unknown id).
std::string_view effect_id(EffectKind kind);
std::optional<EffectKind> effect_kind(std::string_view id);
/// All kinds, in the contract's order.
std::span<const EffectKind> effect_kinds();

/// The parameters of a kind, in the order of Effect::parameters:
///  tooth_crack              stiffness_loss [-] (fraction of the mesh stiffness lost while the
///                           cracked tooth is in contact), tooth_angle_deg (where the tooth
///                           sits on its gear, from the reference tooth)
///  gear_eccentricity        eccentricity_um (geometric centre to axis of rotation), phase_deg
///  bearing_*_defect         impact_force_n (peak force of one impact), slip [-] (cage speed
///                           loss: defect frequencies shift by it), defect_width_mm (sets the
///                           impact's duration: the time a rolling element takes to cross it)
///  shaft_unbalance          unbalance_kg_m (mass × radius), phase_deg
///  shaft_misalignment       misalignment_mrad (angular, at the coupling), ratio_1x (1× force
///                           over the 2× force), direction_deg (of the offset, from +x)
///  planet_pass_modulation   path_stiffness_mn_m (ring to each measured seat, when a planet
///                           stands at the seat), window_deg (the angular half-width of a
///                           planet's window)
///  housing_resonance        frequency_hz, damping_ratio, mass_kg (the housing mass that
///                           carries the sensor)
std::span<const EffectParameter> effect_parameters(EffectKind kind);

/// An effect of `kind` at `location` with every parameter at its default.
Effect make_effect(EffectKind kind, std::string location);

/// Where an effect of `kind` can sit in `drivetrain` (component ids of the description:
/// gears, bearings, shafts, the ring; planets and planet bearings as "planet1".."planetN",
/// "pb1".."pbN", with "planet" and "pb" meaning the first). housing_resonance: the bearings
/// that carry a measurement point.
std::vector<std::string> effect_locations(const Drivetrain& drivetrain, EffectKind kind);

/// Checks an effect against a drivetrain: a location from effect_locations(), every
/// parameter finite and in its range. false with `error` naming the effect, the field and
/// what was expected.
bool check_effect(const Drivetrain& drivetrain, const Effect& effect, std::string* error);

}  // namespace model
