#pragma once
// The damage channels of a drivetrain: every (gear, failure mode) and every bearing
// whose Palmgren–Miner damage the twin tracks, each with its stress function, its
// cycles per rotor revolution (ISO 6336-6 cycle counting) and its S-N curve.
//
// Mesh slots (the load inputs): a planetary stage with P planets gives 2P meshes,
// "sun-planet<k>" then "planet<k>-ring"; a parallel stage gives one mesh. Bearing
// slots: one per description bearing, the bearing on shaft "planet" once per planet
// ("pb1".."pbP").
//
// Cycle counting, ISO 6336-6 §5: n_i = t_i·n/60·(contacts per revolution). Rather than
// per-gear speeds, each source carries its cycles per ROTOR (carrier) revolution:
//   carrier speed n_c, fixed ring, sun absolute n_s = n_c·(1 + z_r/z_s).
//   sun:     a sun tooth meets each planet once per revolution RELATIVE TO THE CARRIER,
//            n_s − n_c = n_c·z_r/z_s: one source per planet mesh, z_r/z_s cycles each
//            (3·z_r/z_s in all for 3 planets). Counting with the absolute sun speed would
//            overstate the cycles by the factor (1 + z_s/z_r).
//   planet:  relative to the carrier n_p = n_c·z_r/z_p; each tooth meshes once per planet
//            revolution with the sun (one flank) and once with the ring (other flank):
//            contact: two channels (sun-side flank, ring-side flank), z_r/z_p cycles each;
//            bending: the root sees one fully reversed cycle per revolution, counted once at
//            the sun-mesh root stress against an S-N curve scaled by Y_M (Material::
//            reversed_bending_factor, ISO 6336-3 Annex B).
//   ring:    fixed; each ring tooth is passed by every planet once per carrier revolution:
//            one source per planet mesh, 1 cycle each (3 per carrier revolution in all).
//   parallel stage gear: 1 contact per own revolution (speed / rotor speed from Kinematics).
//   bearing: ISO 281 life counts revolutions of the inner relative to the outer ring:
//            shaft speed; planet bearings: planet speed relative to the carrier.
//
// Thread context: ChannelSet is built at start-up (allocates); afterwards its stress and
// load functions are allocation-free and O(1) per source.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "model/drivetrain/description.hpp"
#include "model/fatigue/bearing_life.hpp"
#include "model/fatigue/gear_rating.hpp"
#include "model/fatigue/sn_curve.hpp"

namespace model::fatigue {

inline constexpr std::size_t kMaxMeshes = 16;    // 3 stages with up to 6 planets + spares
inline constexpr std::size_t kMaxBearings = 24;  // description bearings incl. per-planet copies
inline constexpr std::size_t kMaxChannels = 64;  // (gear × mode) + bearings
inline constexpr std::size_t kMaxSources = 8;    // meshes feeding one channel (sun: one per planet)

/// Loads of one model step (real-time input). Slots as in ChannelSet::mesh_id / bearing_id.
struct LoadSample {
  std::array<double, kMaxMeshes>
      mesh_force_n{};  // [N] F_t, transverse tangential at the reference circle
  std::array<double, kMaxBearings> bearing_radial_n{};  // [N] F_r radial reaction
  std::array<double, kMaxBearings> bearing_axial_n{};   // [N] F_a axial reaction
};

enum class FailureMode : std::uint8_t { kContact, kBending, kBearing };
const char* failure_mode_name(FailureMode mode);

struct Source {
  std::uint8_t slot = 0;              // mesh slot (gears) or bearing slot (bearings)
  std::uint8_t gear = 0;              // 0 = pinion, 1 = wheel of the mesh (gears only)
  double cycles_per_rotor_rev = 0.0;  // [-]
};

struct Channel {
  std::string component;  // "sun", "planet1", "ring", "g1", "b3", "pb2"
  std::string detail;     // "sun-side flank", "ring-side flank", ... (may be empty)
  FailureMode mode = FailureMode::kContact;
  SnCurve curve;  // stress [MPa] (gears) or P [N] (bearings)
  std::array<Source, kMaxSources> sources{};
  std::size_t source_count = 0;
  double stress_full_scale = 0.0;  // [MPa or N] suggested histogram range (start-up default)
};

struct ChannelOptions {
  RatingSettings rating{};
  double k_a = 1.0;                          // [-] application factor (1 for dynamic loads)
  KneeBranch branch = KneeBranch::kHaibach;  // S-N beyond the knee
  /// [-] planet load sharing factor K_γ (ISO 6336-1 mesh load factor) of the quasi-static
  /// loads: every planet mesh and planet bearing carries K_γ × its equal share, since the
  /// quasi-static loads have no physics to say which planet carries more. 0: the value
  /// IEC 61400-4 gives for the planet count (planet_load_sharing_factor()). The dynamics
  /// spectrum does not use it: the dynamics model carries the sharing itself.
  double planet_load_sharing = 0.0;
  Lubrication lubrication{};  // ISO 281 a_ISO of the bearings (bearing_life.hpp)
};

/// What a bearing slot's ISO 281 life modification factor is computed from (start-up values).
struct BearingLifeTerms {
  bool applied = false;          // a_ISO in use (lubrication enabled and C_u known), else 1
  double ec_cu_n = 0.0;          // [N] e_C·C_u
  double c0_n = 0.0;             // [N] C0 in use (description or ISO 76)
  double cu_n = 0.0;             // [N] C_u in use (description or from C0)
  double viscosity_mm2_s = 0.0;  // [mm²/s] ν at the operating temperature
  double pitch_diameter_mm = 0.0;
  double rev_per_rotor_rev = 0.0;  // [-] ring revolutions per rotor revolution
  BearingType type = BearingType::kRoller;
};

/// IEC 61400-4:2012's planet load sharing factor K_γ for a planetary stage of `planets`
/// planets (3: 1.10, 4: 1.25, 5: 1.35, 6: 1.44, 7: 1.47; beyond 7 the 7-planet value, the
/// last the table gives; 1 or 2 planets: 1, no sharing to be uneven).
double planet_load_sharing_factor(int planets);

class ChannelSet {
 public:
  /// Builds meshes, bearings and channels of `drivetrain`. On a description it cannot
  /// rate (missing gear, material or stage data, too many slots) valid() is false and
  /// error() names what was wrong.
  ChannelSet(const Drivetrain& drivetrain, const ChannelOptions& options);

  bool valid() const { return error_.empty(); }
  const std::string& error() const { return error_; }

  std::size_t mesh_count() const { return mesh_count_; }
  std::size_t bearing_count() const { return bearing_count_; }
  std::size_t channel_count() const { return channel_count_; }
  const std::string& mesh_id(std::size_t slot) const { return mesh_ids_[slot]; }
  const MeshRating& mesh(std::size_t slot) const { return meshes_[slot]; }
  const std::string& bearing_id(std::size_t slot) const { return bearing_ids_[slot]; }
  /// The bearing of `slot`; its dynamic_rating_n is the rating in use (the description's, or
  /// the one computed from the geometry when the description gives none).
  const Bearing& bearing(std::size_t slot) const { return bearings_[slot]; }
  /// The inputs of the slot's a_ISO (applied == false: a_ISO = 1, and why is in life_note()).
  const BearingLifeTerms& bearing_life(std::size_t slot) const { return life_[slot]; }
  /// ISO 281:2007 a_ISO of a bearing slot at an equivalent load and rotor speed (1 when not
  /// applied). Allocation-free.
  double life_modification(std::size_t slot, double equivalent_load_n, double rotor_rpm) const;
  /// Why a_ISO is not applied to some bearing ("" when it is applied to all or switched off).
  const std::string& life_note() const { return life_note_; }
  const Channel& channel(std::size_t i) const { return channels_[i]; }
  const ChannelOptions& options() const { return options_; }
  /// K_γ the quasi-static loads apply to the planets (1 without a planetary stage).
  double planet_load_sharing() const { return planet_load_sharing_; }

  /// Stress [MPa] (gears) or dynamic equivalent load P [N] (bearings) that source `s` of
  /// channel `c` sees under `loads`. O(1), allocation-free.
  double stress(std::size_t c, std::size_t s, const LoadSample& loads) const;

  /// Quasi-static loads for a rotor torque (FALLBACK spectrum, see load_spectrum.hpp):
  /// F_t = T_member/(d/2), each planet's mesh force K_γ × its equal share (ChannelOptions::
  /// planet_load_sharing), bearing reactions from the static force balance described in
  /// drivetrain_channels.cpp. No dynamics, no K_v.
  LoadSample quasi_static_loads(double rotor_torque_nm) const;

 private:
  std::string error_;
  ChannelOptions options_;
  std::size_t mesh_count_ = 0, bearing_count_ = 0, channel_count_ = 0;
  double planet_load_sharing_ = 1.0;
  std::array<std::string, kMaxMeshes> mesh_ids_{};
  std::array<MeshRating, kMaxMeshes> meshes_{};
  std::array<double, kMaxMeshes> torque_to_ft_per_nm_{};  // [1/m] F_t per rotor torque
  std::array<double, kMaxMeshes> quasi_static_factor_{};  // [-] K_γ for planet meshes, else 1
  std::array<std::string, kMaxBearings> bearing_ids_{};
  std::array<Bearing, kMaxBearings> bearings_{};
  std::array<double, kMaxBearings> torque_to_radial_per_nm_{};      // [1/m] F_r per rotor torque
  std::array<double, kMaxBearings> torque_to_axial_per_nm_{};       // [1/m] F_a per rotor torque
  std::array<double, kMaxBearings> bearing_quasi_static_factor_{};  // [-] K_γ for planet bearings
  std::array<BearingLifeTerms, kMaxBearings> life_{};
  std::string life_note_;
  std::array<Channel, kMaxChannels> channels_{};
};

/// ISO 281:2007 §6.2 / eq. (7): dynamic equivalent radial load P [N] of a radial roller
/// bearing with contact angle α: α = 0 → P = F_r; α ≠ 0 → X, Y from e = 1.5·tan α
/// (single row: F_a/F_r ≤ e: X = 1, Y = 0; else X = 0.4, Y = 0.4·cot α; double row:
/// ≤ e: X = 1, Y = 0.45·cot α; else X = 0.67, Y = 0.67·cot α). Ball bearings are treated
/// as radial (P = F_r) — none of paper-2mw's are.
double equivalent_load_n(const Bearing& bearing, double radial_n, double axial_n);

/// ISO 281:2007 eq. (1): L10 = (C/P)^p million revolutions, p = 3 (ball), 10/3 (roller).
double iso281_exponent(BearingType type);
double l10_million_revs(double dynamic_rating_n, double equivalent_load_n, BearingType type);

}  // namespace model::fatigue
