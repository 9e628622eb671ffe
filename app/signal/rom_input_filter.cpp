// The ROM's input filter: see rom_input_filter.hpp.
#include "signal/rom_input_filter.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace app::signal {

double RomInputFilter::corner_for_first_mode(double first_mode_hz, double residual) {
  // (1 + r²)^(−N/2) = residual → r = √(residual^(−2/N) − 1), f_c = f₁ / r.
  const double r = std::sqrt(std::pow(residual, -2.0 / kOrder) - 1.0);
  return first_mode_hz / r;
}

double RomInputFilter::first_mode_hz(const model::dynamics::RomData& rom) {
  double w = 0.0;
  for (int i = 0; i < model::dynamics::kRomDofs; ++i) {
    const double wi = rom.omega_rad_s[i];
    if (wi > 0.0 && (w == 0.0 || wi < w)) w = wi;
  }
  return w / (2.0 * std::numbers::pi);
}

RomInputFilter::RomInputFilter(const RomInputFilterSettings& settings) : settings_(settings) {
  const double fc = settings_.corner_hz > 0.0 ? settings_.corner_hz : 1.0;
  tau_s_ = 1.0 / (2.0 * std::numbers::pi * fc);
  const double x = std::max(0.0, settings_.period_s) / tau_s_;
  // e^{AT} of the chain ẏ₀ = (u − y₀)/τ, ẏᵢ = (yᵢ₋₁ − yᵢ)/τ: (e^{AT})_{ij} = e^{−x} x^{i−j}/(i−j)!,
  // and the held input's gain: 1 − e^{−x} Σ_{k≤i} xᵏ/k! (the Gamma(i+1) distribution at x).
  double term = std::exp(-x), sum = 0.0;
  for (int k = 0; k < kOrder; ++k) {
    phi_[k] = term;
    sum += term;
    gamma_[k] = 1.0 - sum;
    term *= x / (k + 1);
  }
}

void RomInputFilter::reset(const model::dynamics::RomInputs& in) {
  torque_.y.fill(in.input_torque_nm);
  torque_.previous = in.input_torque_nm;
  speed_.y.fill(in.rotor_speed_rpm);
  speed_.previous = in.rotor_speed_rpm;
  started_ = true;
}

void RomInputFilter::advance(Channel& c, double u) const {
  c.previous = c.y[kOrder - 1];
  std::array<double, kOrder> next{};
  for (int i = 0; i < kOrder; ++i) {
    double v = gamma_[i] * u;
    for (int j = 0; j <= i; ++j) v += phi_[i - j] * c.y[j];
    next[i] = v;
  }
  c.y = next;
}

void RomInputFilter::update(const model::dynamics::RomInputs& target) {
  if (!started_) {
    reset(target);
    return;
  }
  advance(torque_, target.input_torque_nm);
  advance(speed_, target.rotor_speed_rpm);
}

model::dynamics::RomInputs RomInputFilter::at_step(int i, int n) const {
  const double w = n > 0 ? static_cast<double>(i + 1) / n : 1.0;
  const double t0 = torque_.previous, t1 = torque_.y[kOrder - 1];
  const double s0 = speed_.previous, s1 = speed_.y[kOrder - 1];
  return {s0 + w * (s1 - s0), t0 + w * (t1 - t0)};
}

model::dynamics::RomInputs RomInputFilter::output() const {
  return {speed_.y[kOrder - 1], torque_.y[kOrder - 1]};
}

}  // namespace app::signal
