#pragma once
// Kinematics of a drivetrain description: shaft speeds, gear-mesh frequencies
// and rolling-bearing defect frequencies as functions of the rotor speed.
// Built once at start-up (allocates); every query afterwards is O(stages),
// allocation-free and safe on the real-time thread.

#include <array>
#include <cstddef>
#include <optional>
#include <string_view>

#include "model/drivetrain/description.hpp"

namespace model {

/// Defect frequencies of one bearing [Hz], for the current shaft speed.
struct BearingFrequencies {
  double shaft_hz = 0.0;  // [Hz] relative speed of inner to outer ring
  double bpfo_hz = 0.0;   // [Hz] ball pass, outer race
  double bpfi_hz = 0.0;   // [Hz] ball pass, inner race
  double bsf_hz = 0.0;    // [Hz] ball spin
  double ftf_hz = 0.0;    // [Hz] fundamental train (cage)
};

/// Ratios of the bearing defect frequencies to the shaft frequency (geometry only).
/// BPFO = Nb/2·(1 − d/Dp·cosφ), BPFI = Nb/2·(1 + d/Dp·cosφ),
/// BSF = Dp/(2d)·(1 − (d/Dp·cosφ)²), FTF = 1/2·(1 − d/Dp·cosφ).
BearingFrequencies bearing_orders(const Bearing& bearing);

class Kinematics {
 public:
  static constexpr std::size_t kMaxStages = 8;

  explicit Kinematics(const Drivetrain& drivetrain);

  /// Overall speed-up ratio (output shaft speed / rotor speed) [-].
  double overall_ratio() const { return overall_ratio_; }
  /// Speed-up ratio of one stage [-] (output / input speed).
  double stage_ratio(std::size_t stage) const { return stage_ratio_[stage]; }
  std::size_t stage_count() const { return stage_count_; }

  /// Rotation frequency of a shaft [Hz] ("lss", "sun_shaft", ...), or of the
  /// planets relative to the carrier ("planet"); nullopt for an unknown id.
  std::optional<double> shaft_hz(std::string_view shaft, double rotor_rpm) const;
  /// Frequency of the input shaft of stage `stage` [Hz].
  double stage_input_hz(std::size_t stage, double rotor_rpm) const;
  /// Tooth-mesh frequency of stage `stage` [Hz]: z_ring·f_carrier for a planetary
  /// stage with a fixed ring, z_wheel·f_input for a parallel stage.
  double mesh_hz(std::size_t stage, double rotor_rpm) const;
  /// Planet-pass frequency N_planets·f_carrier [Hz] of a planetary stage (0 otherwise).
  double planet_pass_hz(std::size_t stage, double rotor_rpm) const;
  /// Defect frequencies of a bearing of the description; nullopt for an unknown id.
  std::optional<BearingFrequencies> bearing_hz(std::string_view bearing, double rotor_rpm) const;

 private:
  const Drivetrain* drivetrain_;
  std::size_t stage_count_ = 0;
  std::array<double, kMaxStages> stage_ratio_{};
  std::array<double, kMaxStages> input_ratio_{};  // stage input speed / rotor speed
  std::array<double, kMaxStages> mesh_order_{};   // mesh frequency / rotor frequency
  std::array<int, kMaxStages> planets_{};
  double planet_ratio_ = 0.0;  // planet speed rel. carrier / rotor speed
  double overall_ratio_ = 1.0;
};

}  // namespace model
