#pragma once
// Online fatigue accumulator: per damage channel an ISO 6336-6 load-duration
// histogram (time and revolutions spent in each stress bin) and the Palmgren–Miner
// damage D = Σ n_i/N_i, updated once per model step.
//
// Exactness over arbitrarily long runs:
//  - time is counted in integer ticks (the loop's period in ticks is passed in), so
//    Σ_bins ticks == source_count·Σ dt_ticks exactly, for any number of steps (uint64:
//    1.8e19 ticks, 5.8e8 years at 1 ms ticks);
//  - rotor revolutions are counted in integer quanta of 2^-32 rev, each step's increment
//    rounded to the nearest quantum (error ≤ 2^-33 rev per step; capacity 4.3e9 rotor
//    revolutions, ≈ 550 years at 15 rpm);
//  - the damage of record is summed per step with Neumaier compensated summation (the
//    exact n·(1/N(σ)) of the step's stress, no binning error; a bearing's divided by its ISO 281
//    a_ISO at the step's load and speed, ChannelSet::life_modification); histogram_damage()
//    recomputes it from the bins at the bin centres, as ISO 6336-6 does, for comparison (for a
//    bearing without a_ISO: the bins keep no speed).
// Bad steps (non-finite load, non-finite or negative speed, dt = 0) are counted in the
// state and change nothing else.
//
// Per-step cost (tools/accumulator_bench, docs/fatigue.md): each mesh's four stresses come
// from one face-load and one K_α evaluation (MeshRating::stresses), each bearing's P from
// its precomputed e and cot α, and each source's n/N(σ) from the S-N curve's constants
// hoisted to construction: ln N = a + k·ln σ on either side of the knee, one log and one
// exp per source (SnCurve::damage_per_cycle evaluates the knee's pow and logs every call).
// The same formulas reordered: each step's increment agrees with SnCurve's to ~1e-14
// relative (tested to 1e-12).
//
// Thread context: construct, configure and restore() at start-up (allocates once);
// step() is O(channels × sources), allocation-free, lock-free and never blocks: real-time
// safe. state() may be copied by the loop thread at a cycle boundary for persistence.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "model/fatigue/drivetrain_channels.hpp"

namespace model::fatigue {

inline constexpr std::size_t kMaxBins = 256;  // stress bins per channel (+1 overflow)
inline constexpr std::uint32_t kAccumulatorStateVersion = 1;
inline constexpr double kRevQuantum = 1.0 / 4294967296.0;  // [rev] 2^-32

struct AccumulatorConfig {
  double tick_s = 1e-3;      // [s] duration of one tick
  std::uint32_t bins = 200;  // [-] ≤ kMaxBins, uniform bins on [0, full_scale)
  std::array<double, kMaxChannels> full_scale{};  // [MPa or N] per channel; 0 → ChannelSet default
};

/// Persistable state: plain, trivially copyable; the app writes it with a CRC.
struct AccumulatorState {
  std::uint32_t version = kAccumulatorStateVersion;
  std::uint32_t channel_count = 0;
  std::uint32_t bins = 0;
  std::uint32_t reserved = 0;
  std::uint64_t config_hash = 0;    // FNV-1a of channel ids, bins, ranges, tick
  std::uint64_t elapsed_ticks = 0;  // valid steps only
  std::uint64_t rotor_rev_q = 0;    // [2^-32 rev]
  std::uint64_t valid_steps = 0;
  std::uint64_t bad_load_steps = 0;   // a non-finite mesh force or bearing load
  std::uint64_t bad_speed_steps = 0;  // non-finite or negative rotor speed
  std::uint64_t zero_dt_steps = 0;
  std::array<std::array<std::uint64_t, kMaxBins + 1>, kMaxChannels> bin_ticks{};
  std::array<std::array<std::uint64_t, kMaxBins + 1>, kMaxChannels> bin_rev_q{};
  std::array<double, kMaxChannels> damage{};        // Neumaier sum
  std::array<double, kMaxChannels> damage_comp{};   // Neumaier compensation
  std::array<double, kMaxChannels> overflow_max{};  // [MPa or N] largest stress above range
};

enum class StepResult : std::uint8_t { kAccumulated, kBadLoad, kBadSpeed, kZeroDt };

class DamageAccumulator {
 public:
  DamageAccumulator(const ChannelSet& channels, const AccumulatorConfig& config);

  /// One model step. @param loads mesh forces [N] and bearing loads [N];
  /// @param rotor_speed_rpm [rpm] ≥ 0; @param dt_ticks step length in ticks.
  StepResult step(const LoadSample& loads, double rotor_speed_rpm, std::uint32_t dt_ticks);

  /// Palmgren–Miner damage of channel c (compensated per-step sum) [-].
  double damage(std::size_t c) const { return state_->damage[c] + state_->damage_comp[c]; }
  /// Damage recomputed from the histogram at bin centres (overflow at its maximum) [-].
  double histogram_damage(std::size_t c) const;
  /// Width of the stress bins of channel c [MPa or N].
  double bin_width(std::size_t c) const { return width_[c]; }
  double elapsed_s() const { return static_cast<double>(state_->elapsed_ticks) * config_.tick_s; }
  double rotor_revolutions() const {
    return static_cast<double>(state_->rotor_rev_q) * kRevQuantum;
  }

  const AccumulatorState& state() const { return *state_; }
  /// Resumes from a persisted state; false (state unchanged) if version, channel count,
  /// bins or configuration hash differ.
  bool restore(const AccumulatorState& saved);
  void reset();
  const ChannelSet& channels() const { return *channels_; }
  const AccumulatorConfig& config() const { return config_; }

 private:
  const ChannelSet* channels_;
  AccumulatorConfig config_;
  std::array<double, kMaxChannels> width_{};  // [MPa or N] bin width
  std::array<double, kMaxChannels> inv_width_{};
  std::unique_ptr<AccumulatorState> state_;
  std::uint64_t config_hash_ = 0;

  // n/N(σ) = exp(−ln N(σ)), ln N = ln_n1 − k1·ln σ above the knee stress, else
  // ln_n2 − k2·ln σ (knee: where ln N passes ln_knee; none: ln_knee = +inf).
  struct CurveConstants {
    double ln_n1 = 0.0, k1 = 0.0;
    double ln_n2 = 0.0, k2 = 0.0;
    double ln_knee = 0.0;
  };
  std::array<CurveConstants, kMaxChannels> curve_{};
  // ISO 281 equivalent-load constants per bearing slot (equivalent_load_n's e and cot α).
  struct BearingConstants {
    bool radial_only = true;
    bool single_row = true;
    double e = 0.0, cot = 0.0;
  };
  std::array<BearingConstants, kMaxBearings> bearing_{};
};

}  // namespace model::fatigue
