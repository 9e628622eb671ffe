#pragma once
// The ROM's inputs between SCADA updates, held regime: each SCADA value stands for its
// whole interval (a 10-minute mean of an export, the supervisor's held or steady-state
// substitute) and the loop holds it; rotor torque and speed then pass through a fourth-order
// critically damped low-pass (four equal first-order sections, time constant τ) whose corner
// sits a factor below the drivetrain's first torsional mode. Point samples (a Modbus poll
// every second) take the other regime, app/signal/scada_interpolator.hpp.
//
// Why. A held value that steps is a force step on the model: it rings the drivetrain's
// lowest torsional mode (paper-2mw: 2.05 Hz, 20 % of critical damping) and the accumulator
// counts the ringing at the S-N curves' steep slopes (k = 17–33 past the knees): one step
// from 50 % to 80 % of rated torque adds 24.7 % to the damage of the 10 s around it
// (g1/g2; tests/app/signal/test_rom_input_transients.cpp). Nothing in the turbine makes such
// steps; the filter removes them and keeps the levels: through it the same step costs what
// its levels cost, to 0.12 %.
//
// The choice, reasoned:
//  - Bandwidth from the physics, not from the SCADA rate: a step through the filter leaves
//    the first mode a free vibration of at most |H(f₁)| = (1 + (f₁/f_c)²)^(−2) of the step's
//    static deflection; f_c = f₁/3 gives 1 %. The transition then takes ~4τ = 0.9 s, nothing
//    against a 10-minute interval (the levels, and so `drivetwin damage`'s per-row damage,
//    are kept to within the transitions' share of the time).
//  - Critically damped (equal real poles): the step response is the Gamma(4, τ) distribution
//    function, monotone — no overshoot that would itself be counted — and C². Unit DC gain:
//    a level is reached exactly, the integral of the input (energy, revolutions) is kept and
//    only delayed by 4τ.
//  - Not for point samples: filtering the held staircase of 1 Hz samples also flattens a real
//    change's extremes (a 0.1 Hz gust of ±20 %: −10 % damage at f₁/3, measured in the same
//    test); the interpolator keeps the samples' values.
// Discretisation: exact for an input held over each cycle (the cascade's matrix exponential,
// closed form: a lower-triangular Toeplitz matrix of e^{−x} xᵏ/k!, x = T/τ); within a cycle
// the ROM's steps take the straight line between the last cycle's output and this one's.
//
// Thread context: construct at start-up; reset()/update()/at_step() on the RT thread:
// fixed size, no allocation, no locks, no clock (the period is a setting).

#include <array>

#include "model/dynamics/rom.hpp"

namespace app::signal {

struct RomInputFilterSettings {
  double corner_hz = 0.6;  // [Hz] 1/(2πτ) of each section
  double period_s = 1e-3;  // [s] the loop's cycle period (update() interval)
};

class RomInputFilter {
 public:
  static constexpr int kOrder = 4;
  /// The first torsional mode's residual after a step, by default: 1 % → f_c = f₁/3.
  static constexpr double kDefaultResidual = 0.01;

  /// f_c for which a step leaves `residual` of its static deflection ringing at f₁ [Hz]:
  /// (1 + (f₁/f_c)²)^(−kOrder/2) = residual.
  static double corner_for_first_mode(double first_mode_hz, double residual = kDefaultResidual);
  /// The lowest retained natural frequency of a ROM [Hz] (0 for an empty model).
  static double first_mode_hz(const model::dynamics::RomData& rom);

  explicit RomInputFilter(const RomInputFilterSettings& settings);

  /// Starts at rest at `in` (the first valid inputs): output = in, no transition.
  void reset(const model::dynamics::RomInputs& in);
  /// One cycle with the inputs the loop holds over it (the supervisor's decision).
  void update(const model::dynamics::RomInputs& target);
  /// The inputs for ROM step i (0 … n−1) of this cycle: linear from the previous cycle's
  /// output to this cycle's (step n−1 reaches it).
  model::dynamics::RomInputs at_step(int i, int n) const;
  /// This cycle's output.
  model::dynamics::RomInputs output() const;
  bool started() const { return started_; }
  double time_constant_s() const { return tau_s_; }
  const RomInputFilterSettings& settings() const { return settings_; }

 private:
  struct Channel {
    std::array<double, kOrder> y{};  // section outputs; y[kOrder−1] is the output
    double previous = 0.0;           // output at the end of the previous cycle
  };
  void advance(Channel& c, double u) const;

  RomInputFilterSettings settings_;
  double tau_s_ = 1.0;
  // Exact one-period propagator: y⁺_i = Σ_{j≤i} phi_[i−j]·y_j + gamma_[i]·u.
  std::array<double, kOrder> phi_{};
  std::array<double, kOrder> gamma_{};
  Channel torque_{}, speed_{};
  bool started_ = false;
};

}  // namespace app::signal
