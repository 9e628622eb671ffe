// The ROM's inputs per model step: see rom_input_shaper.hpp.
#include "signal/rom_input_shaper.hpp"

#include <chrono>

namespace app::signal {

namespace {
RomInputFilterSettings filter_settings(const model::dynamics::RomData& rom, double cycle_s) {
  const double f1 = RomInputFilter::first_mode_hz(rom);
  return {f1 > 0.0 ? RomInputFilter::corner_for_first_mode(f1) : 1.0, cycle_s};
}
}  // namespace

RomInputShaper::RomInputShaper(const model::dynamics::RomData& rom, double cycle_s,
                               double scada_period_s)
    : regime_(scada_period_s > kMaxInterpolationPeriod ? Regime::kFilter : Regime::kInterpolate),
      cycle_s_(cycle_s),
      first_mode_hz_(RomInputFilter::first_mode_hz(rom)),
      filter_(filter_settings(rom, cycle_s)),
      interpolator_(scada_period_s > 0.0 ? scada_period_s : 1.0) {}

void RomInputShaper::reset(hal::Timestamp now, const model::dynamics::RomInputs& in) {
  filter_.reset(in);
  interpolator_ = ScadaInterpolator(interpolator_.delay_s() / 2.0);
  interpolator_.sample(now, in);
  begin_ = end_ = in;
}

void RomInputShaper::cycle(hal::Timestamp now, const model::dynamics::RomInputs& held,
                           bool new_sample) {
  if (regime_ == Regime::kFilter) {
    filter_.update(held);
    return;
  }
  if (new_sample) interpolator_.sample(now, held);
  const auto period =
      std::chrono::duration_cast<hal::Timestamp>(std::chrono::duration<double>(cycle_s_));
  begin_ = interpolator_.at(now);
  end_ = interpolator_.at(now + period);
}

model::dynamics::RomInputs RomInputShaper::at_step(int i, int n) const {
  if (regime_ == Regime::kFilter) return filter_.at_step(i, n);
  const double w = n > 0 ? static_cast<double>(i + 1) / n : 1.0;
  return {begin_.rotor_speed_rpm + w * (end_.rotor_speed_rpm - begin_.rotor_speed_rpm),
          begin_.input_torque_nm + w * (end_.input_torque_nm - begin_.input_torque_nm)};
}

}  // namespace app::signal
