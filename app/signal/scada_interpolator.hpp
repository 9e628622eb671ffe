#pragma once
// The ROM's inputs from SCADA point samples (a Modbus poll every second or so): a
// shape-preserving cubic (PCHIP, Fritsch–Carlson) through the samples at their own times,
// evaluated a fixed delay behind the loop — the interpolation regime of the ROM's inputs
// (app/signal/rom_input_filter.hpp explains the problem and the held regime used for
// interval means such as 10-minute exports).
//
// Why this for point samples. The samples are the turbine's rotor torque and speed at the
// poll instants; what happened between them is unknown but smooth (the rotor's inertia). A
// held value that steps rings the drivetrain's first torsional mode (counted as damage); a
// low-pass over the held staircase removes the ringing but also flattens every real change's
// extremes (a 0.1 Hz gust of ±20 %: −10 % damage at f₁/3, −4.6 % at f₁/1.5, measured in
// tests/app/signal/test_rom_input_transients.cpp). An interpolant through the samples keeps
// their values — the load levels the SCADA saw — and joins them with C¹ curves that take a
// whole sample period, too slow to ring a mode that lies above the SCADA's Nyquist
// frequency. PCHIP: monotone between samples (no overshoot that would itself be counted;
// a step moves in one S-shaped sample period), the exact line through a ramp, and a flat
// tangent at every local extreme, so a peak is reached, never exceeded.
//
// Timing. The value at loop time t is the interpolant at t − D, D = 2 × the nominal sample
// period: the segment around t − D and both its tangents (which need one sample beyond it)
// are then known. A sample that arrives after a gap of more than 1.5 periods is preceded by
// a copy of the last value one period before it (hold through the gap, then one period of
// transition); past the newest sample the value is held (SCADA stale: the supervisor decides
// what to feed in, and its choice arrives here as a sample).
//
// Thread context: RT thread only after construction: fixed ring, no allocation, no clock.

#include <array>
#include <cstddef>
#include <cstdint>

#include "hal/clock.hpp"
#include "model/dynamics/rom.hpp"

namespace app::signal {

class ScadaInterpolator {
 public:
  /// Samples kept: the segment around t − D needs its two ends and one neighbour each.
  static constexpr std::size_t kCapacity = 8;

  /// @param period_s the nominal sample period (the poll interval) [s], > 0.
  explicit ScadaInterpolator(double period_s);

  /// A new sample (SCADA values, or the supervisor's substitute) taken at `stamp`. Samples
  /// not after the newest are ignored (counted).
  void sample(hal::Timestamp stamp, const model::dynamics::RomInputs& in);
  /// The inputs at loop time `now` (the interpolant at now − delay). Before any sample:
  /// zeros, `started()` false.
  model::dynamics::RomInputs at(hal::Timestamp now) const;
  bool started() const { return count_ > 0; }
  double delay_s() const { return delay_s_; }
  std::uint64_t ignored() const { return ignored_; }

 private:
  struct Point {
    double t = 0.0;            // [s]
    double v[2] = {0.0, 0.0};  // speed [rpm], torque [N·m]
  };
  const Point& point(std::size_t i) const;  // i-th oldest of count_
  void push(const Point& p);
  double tangent(std::size_t k, int channel) const;

  double period_s_;
  double delay_s_;
  std::array<Point, kCapacity> ring_{};
  std::size_t head_ = 0, count_ = 0;
  std::uint64_t ignored_ = 0;
};

}  // namespace app::signal
