#pragma once
// One-degree-of-freedom rotor driven by a wind time series: what turns turbulent
// wind into the gearbox input torque, with the turbine's speed and pitch control.
//
//   J·dω/dt = T_aero(v, ω, β) − T_gen(ω, ...)          J = J_rotor + J_drivetrain
//   T_aero  = ½ρπR²v³·Cp(ωR/v, β)/ω                     (WindLoad::aerodynamic_torque_nm,
//                                                        the description's Cp surface)
//   T_lss   = T_aero − J_rotor·dω/dt = T_gen + J_drivetrain·dω/dt   (gearbox input torque)
//
// T_gen is the generator torque referred to the low-speed shaft; J_drivetrain is the
// generator's (and gearbox's) inertia referred to it (J·i²). The shaft between rotor and
// gearbox is rigid here: drivetrain torsional modes are the dynamics model's business.
//
// Controller (the steady states are those of model/wind/wind_load.hpp's regions):
//   region 2   T_gen = k_opt·ω², k_opt = ½ρπR⁵·Cp_max/λ_opt³: the rotor settles at λ_opt
//              (T_aero(v, λ_opt·v/R) = k_opt·ω² exactly).
//   min speed  when the description has a minimum rotor speed ω_min > 0, T_gen is
//              k_opt·ω² scaled down linearly to 0 between ω_min and 0.95·ω_min: the
//              rotor settles within 5 % below ω_min (the steady model clamps at ω_min).
//   region 2½  a PI speed loop on the generator torque holds ω_rated:
//              T_gen = clamp(Kp·e + I, k_opt·ω², T_rated), e = ω − ω_rated, the integrator
//              clamped with the output (no wind-up), so below rated speed T_gen = k_opt·ω².
//              In steady state T_gen = T_aero(v, ω_rated, 0) — the aerodynamic torque at
//              rated speed, not the steady model's ramp in v (for paper-2mw the ramp is 0.5 %
//              below it at 10 m/s and 9 % above it at 12 m/s, see wind_load.hpp).
//   region 3   constant torque T_rated (what the steady model gives) while the blades pitch
//              (where the surface can deliver T_rated at rated speed at all: paper-2mw's
//              Heier surface does so only between ≈ 13.9 and ≈ 16.2 m/s and needs < 0.5° of
//              pitch there; above, even unpitched, T_aero < T_rated and the torque loop runs):
//              a PI speed loop on β, β = clamp(Kp_β·e + I_β, 0, β_max), rate ≤ 8°/s, active
//              only while T_gen is at T_rated or β > 0 (so the two loops never fight).
// Both loops are placed by pole placement on the linearised rotor, J·s² + K_p·G·s + K_i·G
// with natural frequency 0.6 rad/s and damping ratio 0.7 (the pitch loop's values of
// Jonkman et al., NREL/TP-500-38060, 2009, §7.4); G = 1 for the torque loop and
// G = −∂T_aero/∂β for the pitch loop, gain-scheduled on β from a table of the region-3
// steady states (ω_rated, T_aero = T_rated) built at construction.
//
// Integration: explicit Euler on ω with the controller evaluated at the start of the
// step and the pitch rate-limited; the step is the caller's (fixed) dt. Time is passed in:
// the wind of the step is the caller's.
//
// Thread context: construct at start-up (builds the pitch gain table; no allocation);
// step() is pure, allocation-free and exception-free.

#include <array>
#include <cstddef>

#include "model/drivetrain/description.hpp"
#include "model/wind/wind_load.hpp"

namespace model::wind {

struct RotorModelParameters {
  /// Rotor (hub + three blades) polar inertia [kg·m²]. Not in the drivetrain description
  /// nor the paper; 5.0e6 kg·m² is ASSUMED for an 82 m, 2 MW rotor: NREL's 5 MW rotor
  /// (R = 63 m, ≈ 3.9e7 kg·m²) scaled with R^4.5–R^5 (blade mass ∝ R^2.5–R^3) gives
  /// 4.5e6–5.6e6.
  double rotor_inertia_kg_m2 = 5.0e6;
  /// Generator + gearbox inertia referred to the low-speed shaft [kg·m²] (J_gen·i²).
  double drivetrain_inertia_kg_m2 = 0.0;
  double loop_natural_frequency_rad_s = 0.6;          // [rad/s] both speed loops
  double loop_damping_ratio = 0.7;                    // [-]
  double max_pitch_rad = 0.5235987755982988;          // [rad] 30°
  double max_pitch_rate_rad_s = 0.13962634015954636;  // [rad/s] 8°/s
};

/// Whether the parameters are usable with the turbine; else *what names the field.
bool valid_rotor_parameters(const Turbine& turbine, const RotorModelParameters& p,
                            const char** what);

struct RotorState {
  double speed_rad_s = 0.0;         // [rad/s] ω
  double pitch_rad = 0.0;           // [rad] β
  double torque_integral_nm = 0.0;  // [N·m] I of the torque loop
  double pitch_integral_rad = 0.0;  // [rad] I_β of the pitch loop
};

struct RotorStepOutput {
  double aero_torque_nm = 0.0;       // [N·m] T_aero during the step
  double generator_torque_nm = 0.0;  // [N·m] T_gen (low-speed shaft side)
  double shaft_torque_nm = 0.0;      // [N·m] T_lss = T_aero − J_rotor·dω/dt
  double acceleration_rad_s2 = 0.0;  // [rad/s²] dω/dt during the step
  double speed_rad_s = 0.0;          // [rad/s] ω at the start of the step
  double pitch_rad = 0.0;            // [rad] β during the step
  double electrical_power_w = 0.0;   // [W] η·T_gen·ω − P_0 (WindLoad::electrical_power_w)
};

class RotorModel {
 public:
  static constexpr std::size_t kPitchTablePoints = 48;

  RotorModel(const Turbine& turbine, const RotorModelParameters& parameters);

  /// The equilibrium for a constant wind (the state the controller settles in).
  RotorState steady_state(double wind_speed_mps) const;

  /// One step of dt seconds with wind v held over the step; advances `state`.
  RotorStepOutput step(RotorState& state, double wind_speed_mps, double dt_s) const;

  /// T_gen of the controller for a state and speed error, and what the loops do (no
  /// integration); exposed for tests.
  double generator_torque_nm(const RotorState& state) const;

  double optimal_mode_gain() const { return k_opt_; }  // [N·m·s²] k_opt
  double total_inertia_kg_m2() const { return inertia_; }
  const WindLoad& wind_load() const { return wind_; }
  /// −∂T_aero/∂β at the region-3 steady state with pitch β [N·m/rad] (gain schedule).
  double pitch_sensitivity_nm_rad(double pitch_rad) const;

 private:
  double region2_torque_nm(double speed_rad_s) const;

  WindLoad wind_;
  RotorModelParameters p_;
  double inertia_ = 0.0;                                 // [kg·m²] J
  double k_opt_ = 0.0;                                   // [N·m·s²]
  double rated_speed_ = 0.0;                             // [rad/s]
  double min_speed_ = 0.0;                               // [rad/s]
  double rated_torque_ = 0.0;                            // [N·m]
  double radius_ = 0.0;                                  // [m] R
  double torque_kp_ = 0.0;                               // [N·m·s/rad]
  double torque_ki_ = 0.0;                               // [N·m/rad]
  std::array<double, kPitchTablePoints> table_pitch_{};  // [rad], increasing
  std::array<double, kPitchTablePoints> table_dtdb_{};   // [N·m/rad], −∂T/∂β > 0
  std::size_t table_size_ = 0;
};

}  // namespace model::wind
