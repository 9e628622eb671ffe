#pragma once
// The ROM's inputs per model step from what the loop holds per cycle: the one place the
// loop asks. It picks the regime from the SCADA's sample period:
//   ≤ kMaxInterpolationPeriod (a Modbus poll, a recording's 1 Hz rows): point samples →
//     ScadaInterpolator (PCHIP through the samples, 2 periods behind; scada_interpolator.hpp);
//   longer (10-minute means of an export): held values → RomInputFilter (critically damped
//     at f₁/3, f₁ the ROM's first mode; rom_input_filter.hpp).
// Both keep the levels the SCADA gave and remove the steps that ring the drivetrain's first
// torsional mode (docs/dynamics.md, "The ROM's inputs between SCADA samples").
//
// Thread context: construct at start-up; reset()/cycle()/at_step() on the RT thread only
// (fixed size, no allocation, no clock: `now` is passed in).

#include "hal/clock.hpp"
#include "model/dynamics/rom.hpp"
#include "signal/rom_input_filter.hpp"
#include "signal/scada_interpolator.hpp"

namespace app::signal {

class RomInputShaper {
 public:
  /// Longest sample period treated as point samples [s]: beyond it a value stands for an
  /// interval (no SCADA polls that slowly; exports average over 1–10 minutes).
  static constexpr double kMaxInterpolationPeriod = 10.0;
  enum class Regime : std::uint8_t { kInterpolate, kFilter };

  /// @param rom the running model (its first mode sets the filter); @param cycle_s the loop's
  /// period [s]; @param scada_period_s the SCADA's sample period [s] (0: unknown → 1 s).
  RomInputShaper(const model::dynamics::RomData& rom, double cycle_s, double scada_period_s);

  /// Starts at rest at `in` (the first valid inputs), at loop time `now`.
  void reset(hal::Timestamp now, const model::dynamics::RomInputs& in);
  /// One cycle at `now` with the inputs the loop holds (the supervisor's); `new_sample`: they
  /// are a new SCADA sample or a new substitute (source changed).
  void cycle(hal::Timestamp now, const model::dynamics::RomInputs& held, bool new_sample);
  /// ROM step i (0 … n−1) of this cycle.
  model::dynamics::RomInputs at_step(int i, int n) const;

  Regime regime() const { return regime_; }
  double first_mode_hz() const { return first_mode_hz_; }
  const RomInputFilter& filter() const { return filter_; }
  const ScadaInterpolator& interpolator() const { return interpolator_; }

 private:
  Regime regime_;
  double cycle_s_;
  double first_mode_hz_;
  RomInputFilter filter_;
  ScadaInterpolator interpolator_;
  model::dynamics::RomInputs begin_{}, end_{};  // interpolator: at the cycle's start and end
};

}  // namespace app::signal
