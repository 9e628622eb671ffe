#pragma once
// The kinematic signature catalogue: every effect of the diagnosis contract
// (shared/reference/diagnosis-report.md) at every location of a drivetrain, as a
// hypothesis with the lines it adds to the vibration, all computed from the
// drivetrain description's kinematics (model/drivetrain/kinematics.hpp) — never from
// a particular recording.
//
// Orders are cycles per revolution of the reference shaft (the fastest shaft: the hss
// of paper-2mw, where a tacho sits), so the catalogue holds at every speed.
//
//  effect                     lines (h: mesh harmonic, k: sideband / harmonic index)
//  tooth_crack @ gear g       spectrum: h·f_mesh ± k·f_g, k = 1..K_crack, and k·f_g
//                             (an impulsive modulation once per revolution of g: a broad
//                             sideband family); for the sun of a planetary stage f_g is
//                             its speed relative to the carrier, and N_planets·f_g too
//  gear_eccentricity @ g      spectrum: h·f_mesh ± k·f_g, k = 1..2, and 1·f_g (a
//                             sinusoidal modulation: a narrow family)
//  bearing_outer_race_defect  envelope: k·BPFO
//  bearing_inner_race_defect  envelope: k·BPFI ± j·f_shaft, j = 0, 1, 2 (load zone)
//  bearing_ball_defect        envelope: k·2·BSF ± j·FTF, j = 0, 1 (cage)
//                             bearing lines may lie `slip` (relative) off nominal
//  shaft_unbalance @ s        spectrum: 1·f_s
//  shaft_misalignment @ s     spectrum: 2·f_s and 1·f_s (and 3·f_s, weaker)
//  planet_pass_modulation     spectrum: h·f_mesh,planetary ± k·N_planets·f_carrier
//    @ ring
//  housing_resonance @ b      no kinematic line: every line of the channel measured at b
//                             amplified in one band (band evidence, see locate.hpp)
//
// Thread context: built once off the real-time thread (allocates); read-only after.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "model/drivetrain/description.hpp"
#include "model/drivetrain/kinematics.hpp"

namespace model::diagnosis {

enum class Effect : std::uint8_t {
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
inline constexpr std::size_t kEffectCount = 9;

/// The contract's id ("tooth_crack", ...).
const char* effect_id(Effect effect);
std::optional<Effect> effect_from_id(std::string_view id);

/// A rolling-element bearing defect (an impact train with slip).
inline bool is_bearing(Effect effect) {
  return effect == Effect::kBearingOuterRaceDefect || effect == Effect::kBearingInnerRaceDefect ||
         effect == Effect::kBearingBallDefect;
}

/// Where a line is looked for: the order spectrum of the waveform, or of its squared
/// envelope in the band where impacts ring.
enum class Domain : std::uint8_t { kSpectrum, kEnvelope };

/// A kinematic family of lines: what the locate step names a residual feature by.
struct Family {
  Domain domain = Domain::kSpectrum;
  std::string text;             // "sidebands of the high-speed mesh spaced at the hss speed"
  double spacing_order = 0.0;   // [orders] the family's characteristic rate (printed in Hz)
  std::vector<double> orders;   // [orders] the lines
  std::vector<double> weights;  // [-] expected relative importance of each line (1: primary)
  double tolerance = 0.0;       // [-] relative: a line may lie order·(1 ± tolerance) (slip)
};

/// A line a hypothesis predicts.
struct SignatureLine {
  double order = 0.0;   // [orders]
  double weight = 1.0;  // [-] 1: a primary line; less: a line that may be weak
};

/// One hypothesis: an effect at a location with its kinematic signature.
struct Hypothesis {
  Effect effect = Effect::kToothCrack;
  std::string location;               // component id of the drivetrain
  Domain domain = Domain::kSpectrum;  // where its lines are looked for
  std::vector<SignatureLine> lines;   // empty for housing_resonance (band evidence)
  double tolerance = 0.0;             // [-] relative position tolerance of its lines (slip)
  double rate_order = 0.0;            // [orders] the rate it repeats at (gear, shaft, defect)
  std::size_t family = 0;             // index into Catalogue::families: how its lines are named
  std::string shaft;                  // shaft whose synchronous average it changes ("" none)
  std::string explanation;            // the physics, one sentence
};

struct CatalogueConfig {
  int mesh_harmonics = 3;   // [-] h = 1..H
  int crack_sidebands = 5;  // [-] K_crack
  int eccentricity_sidebands = 2;
  int bearing_harmonics = 3;  // [-] k = 1..3
  // A bearing's lines in the waveform's spectrum: every harmonic of its rate up to this
  // order (the top of the envelope's synchronous comb, locate.hpp), at most this many.
  double bearing_spectrum_top_order = 60.0;       // [orders]
  int bearing_spectrum_harmonics = 12;            // [-]
  double bearing_spectrum_min_shaft_order = 0.2;  // [orders] kSynchronousShaftOrder
  double slip = 0.02;      // [-] rolling-element slip tolerance on bearing lines
  double max_order = 1e9;  // [orders] lines above are dropped (analysis band)
};

/// Rate of a rotating part in orders of the reference shaft.
struct PartRate {
  std::string id;
  double order = 0.0;
};

struct Catalogue {
  std::string reference_shaft;       // the shaft orders refer to
  double reference_per_rotor = 1.0;  // [-] reference speed / rotor speed
  std::vector<PartRate> shafts;      // every shaft of the description (and "planet", relative)
  std::vector<PartRate> meshes;      // per stage: mesh order (id: stage id)
  std::vector<Family> families;
  std::vector<Hypothesis> hypotheses;

  /// Reference shaft frequency [Hz] at a rotor speed.
  double reference_hz(double rotor_rpm) const { return rotor_rpm / 60.0 * reference_per_rotor; }
  const PartRate* shaft(std::string_view id) const;
};

/// Builds the catalogue of `drivetrain`. `sensor_locations` are the bearings that carry a
/// measurement channel (the locations of housing_resonance).
Catalogue build_catalogue(const Drivetrain& drivetrain,
                          const std::vector<std::string>& sensor_locations,
                          const CatalogueConfig& config = {});

}  // namespace model::diagnosis
