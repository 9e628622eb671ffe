#pragma once
// Broadband vibration of one CMS measurement point evaluated in the zones of ISO 10816-21
// (Mechanical vibration — Evaluation of machine vibration by measurements on non-rotating
// parts — Part 21: Horizontal axis wind turbines with gearbox, 2015), for the gearbox:
//
//   quantity (rms over the evaluation period)   band            period   B/C      C/D
//   acceleration                                0.1 Hz – 10 Hz  10 min   0.3      0.5 m/s²
//   acceleration                                10 Hz – 2 kHz   1 min    7.5      12  m/s²
//   velocity                                    10 Hz – 1 kHz   1 min    3.5      5.6 mm/s
//
// The boundaries are those of the standard's informative Annex A (onshore turbines up to
// 3 MW, from about 1000 turbines), the same as VDI 3834-1:2009 Table 1 for the gearbox;
// they are configuration (`vibration.*`, run_config.hpp), so an operator's own limits per
// §8 (ALERT/ALARM from a baseline) replace them without a rebuild. The standard defines no
// A/B boundary for wind turbines: zones A and B are one zone here. Evaluation quantity:
// the interval rms (energy-equivalent mean, §4.2) over the period, band-limited as §5.6
// asks; here by second-order Butterworth high- and low-pass sections at the band edges
// (bilinear transform, pre-warped), velocity by trapezoidal integration between two 10 Hz
// high-passes, the 0.1–10 Hz band after a block mean down to ~100 Hz.
//
// An interval with fewer than kMinCoverage of its expected samples (CMS gaps, bus-off)
// gives no value and zone kUnknown: a zone is never judged on a fraction of the period.
//
// Thread context: construct at start-up; add() and the accessors on the RT thread:
// fixed-size state, no allocation, O(1) per sample.

#include <cstddef>
#include <cstdint>

#include "loop/snapshot.hpp"

namespace app::supervisor {

/// Zone boundaries and evaluation periods (ISO 10816-21 Annex A values by default).
struct ZoneLimits {
  double accel_hf_bc_mps2 = 7.5, accel_hf_cd_mps2 = 12.0;  // [m/s²] 10 Hz–2 kHz
  double velocity_bc_mmps = 3.5, velocity_cd_mmps = 5.6;   // [mm/s] 10 Hz–1 kHz
  double accel_lf_bc_mps2 = 0.3, accel_lf_cd_mps2 = 0.5;   // [m/s²] 0.1–10 Hz
  double hf_interval_s = 60.0;                             // [s]
  double lf_interval_s = 600.0;                            // [s]
};

/// The zone of `value` between the two boundaries.
loop::VibrationZone zone_of(double value, double bc, double cd);

/// A second-order IIR section (transposed direct form II), coefficients normalised by a0.
struct Biquad {
  double b0 = 1.0, b1 = 0.0, b2 = 0.0, a1 = 0.0, a2 = 0.0;
  double z1 = 0.0, z2 = 0.0;
  double step(double x) {
    const double y = b0 * x + z1;
    z1 = b1 * x - a1 * y + z2;
    z2 = b2 * x - a2 * y;
    return y;
  }
  void reset() { z1 = z2 = 0.0; }
};
/// Second-order Butterworth sections at corner `fc_hz` for sample rate `fs_hz`.
Biquad butterworth_lowpass(double fc_hz, double fs_hz);
Biquad butterworth_highpass(double fc_hz, double fs_hz);

class VibrationZones {
 public:
  /// Minimum share of an interval's expected samples for it to be evaluated.
  static constexpr double kMinCoverage = 0.9;

  VibrationZones() = default;
  VibrationZones(const ZoneLimits& limits, double sample_rate_hz);

  /// Feeds `n` consecutive samples [m/s²], after `lost_before` samples that never arrived
  /// (a CMS gap): those count as time in the interval but not as samples, and restart the
  /// filters (their state no longer belongs to the signal).
  void add(const float* samples, std::size_t n, std::size_t lost_before = 0);

  /// The values of the last complete intervals (NaN until there is one) and the zone.
  void fill(loop::PointSnapshot& out) const;
  loop::VibrationZone zone() const;
  /// Intervals completed so far (hf, lf): lets the caller see a new evaluation.
  std::uint64_t hf_intervals() const { return hf_intervals_; }

 private:
  void end_hf_interval();
  void end_lf_interval();

  ZoneLimits limits_{};
  double fs_ = 0.0;
  // 10 Hz–2 kHz acceleration.
  Biquad hf_hp_, hf_lp_;
  // 10 Hz–1 kHz velocity: HP → trapezoidal integral → HP → LP.
  Biquad v_hp1_, v_hp2_, v_lp_;
  double v_prev_in_ = 0.0, v_integral_ = 0.0;
  // 0.1–10 Hz acceleration on a block mean.
  std::size_t lf_decimation_ = 1;
  double lf_fs_ = 0.0;
  Biquad lf_hp_, lf_lp_;
  double lf_block_sum_ = 0.0;
  std::size_t lf_block_n_ = 0;

  // Running sums of the current intervals.
  double hf_sum2_ = 0.0, v_sum2_ = 0.0;
  double raw_sum1_ = 0.0, raw_sum2_ = 0.0, raw_sum3_ = 0.0, raw_sum4_ = 0.0;
  std::size_t hf_n_ = 0, hf_expected_ = 0;
  double lf_sum2_ = 0.0;
  std::size_t lf_n_ = 0, lf_expected_ = 0;
  std::size_t hf_clock_ = 0, lf_clock_ = 0;  // samples since the interval began (incl. gaps)

  // Results of the last complete intervals.
  double accel_hf_ = -1.0, velocity_mmps_ = -1.0, accel_lf_ = -1.0;  // < 0: none
  double rms_ = -1.0, kurtosis_ = -1.0;
  std::uint64_t hf_intervals_ = 0;
};

}  // namespace app::supervisor
