#include "model/wind/rotor_model.hpp"

#include "units.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace model::wind {

namespace {
constexpr double kMinSpeedRampStart = 0.95;  // T_gen → 0 at 0.95·ω_min (header)
constexpr double kPitchStepRad = 0.1 * std::numbers::pi / 180.0;  // finite difference, 0.1°
constexpr int kBisections = 80;

// Root of f on [lo, hi] by bisection, f(lo) and f(hi) of opposite signs (else lo or hi,
// whichever |f| is smaller).
template <class F>
double bisect(F f, double lo, double hi) {
  double f_lo = f(lo);
  const double f_hi = f(hi);
  if (f_lo * f_hi > 0.0) return std::abs(f_lo) < std::abs(f_hi) ? lo : hi;
  for (int i = 0; i < kBisections; ++i) {
    const double mid = 0.5 * (lo + hi);
    const double f_mid = f(mid);
    if ((f_mid > 0.0) == (f_lo > 0.0)) {
      lo = mid;
      f_lo = f_mid;
    } else {
      hi = mid;
    }
  }
  return 0.5 * (lo + hi);
}
}  // namespace

bool valid_rotor_parameters(const Turbine& turbine, const RotorModelParameters& p,
                            const char** what) {
  const char* problem = nullptr;
  if (!(p.rotor_inertia_kg_m2 > 0.0) || !std::isfinite(p.rotor_inertia_kg_m2)) {
    problem = "rotor inertia must be > 0";
  } else if (!(p.drivetrain_inertia_kg_m2 >= 0.0) || !std::isfinite(p.drivetrain_inertia_kg_m2)) {
    problem = "drivetrain inertia must be >= 0";
  } else if (!(p.loop_natural_frequency_rad_s > 0.0) || !(p.loop_damping_ratio > 0.0)) {
    problem = "speed loop natural frequency and damping must be > 0";
  } else if (!(p.max_pitch_rad > 0.0) || !(p.max_pitch_rate_rad_s > 0.0)) {
    problem = "maximum pitch and pitch rate must be > 0";
  } else if (!(turbine.rated_rotor_speed_rpm > 0.0) || !(turbine.rated_torque_nm > 0.0) ||
             !(turbine.rotor_radius_m > 0.0)) {
    problem = "turbine rated speed, rated torque and rotor radius must be > 0";
  }
  if (what != nullptr) *what = problem;
  return problem == nullptr;
}

RotorModel::RotorModel(const Turbine& turbine, const RotorModelParameters& parameters)
    : wind_(turbine), p_(parameters) {
  inertia_ = p_.rotor_inertia_kg_m2 + p_.drivetrain_inertia_kg_m2;
  rated_speed_ = turbine.rated_rotor_speed_rpm * kRpmToRadS;
  min_speed_ = turbine.min_rotor_speed_rpm * kRpmToRadS;
  rated_torque_ = turbine.rated_torque_nm;
  radius_ = turbine.rotor_radius_m;
  const double r = radius_;
  const CpPeak& peak = wind_.cp_peak();
  // k_opt = ½ρπR⁵·Cp_max/λ_opt³: T_aero at λ_opt is k_opt·ω² (header).
  if (peak.lambda_opt > 0.0) {
    k_opt_ = 0.5 * turbine.air_density_kg_m3 * std::numbers::pi * r * r * r * r * r * peak.cp_max /
             (peak.lambda_opt * peak.lambda_opt * peak.lambda_opt);
  }
  const double wn = p_.loop_natural_frequency_rad_s;
  torque_kp_ = 2.0 * p_.loop_damping_ratio * wn * inertia_;
  torque_ki_ = wn * wn * inertia_;

  // Pitch gain schedule: region-3 steady states (ω_rated, T_aero = T_rated) from the rated
  // wind to cut-out; −∂T/∂β by central differences.
  const double v_lo = turbine.rated_wind_mps;
  const double v_hi = std::max(turbine.cut_out_wind_mps, v_lo + 1.0);
  auto sensitivity = [&](double v, double beta) {
    const double b0 = std::max(0.0, beta - kPitchStepRad);
    const double b1 = beta + kPitchStepRad;
    return -(wind_.aerodynamic_torque_nm(v, rated_speed_, b1) -
             wind_.aerodynamic_torque_nm(v, rated_speed_, b0)) /
           (b1 - b0);
  };
  for (std::size_t i = 0; i < kPitchTablePoints; ++i) {
    const double v =
        v_lo + (v_hi - v_lo) * static_cast<double>(i) / static_cast<double>(kPitchTablePoints - 1);
    auto excess = [&](double beta) {
      return wind_.aerodynamic_torque_nm(v, rated_speed_, beta) - rated_torque_;
    };
    if (!(excess(0.0) > 0.0) || !(excess(p_.max_pitch_rad) < 0.0)) continue;
    const double beta = bisect(excess, 0.0, p_.max_pitch_rad);
    const double g = sensitivity(v, beta);
    if (!(g > 0.0)) continue;
    if (table_size_ > 0 && beta <= table_pitch_[table_size_ - 1]) continue;
    table_pitch_[table_size_] = beta;
    table_dtdb_[table_size_] = g;
    ++table_size_;
  }
  if (table_size_ == 0) {
    // The surface never needs pitch below cut-out: a single gain at cut-out, β = 0.
    const double g = sensitivity(v_hi, 0.0);
    table_pitch_[0] = 0.0;
    table_dtdb_[0] = g > 0.0 ? g : rated_torque_;  // 1 N·m per rad per N·m: a weak loop
    table_size_ = 1;
  }
}

double RotorModel::pitch_sensitivity_nm_rad(double pitch_rad) const {
  if (table_size_ == 1 || pitch_rad <= table_pitch_[0]) return table_dtdb_[0];
  if (pitch_rad >= table_pitch_[table_size_ - 1]) return table_dtdb_[table_size_ - 1];
  std::size_t k = 1;
  while (k < table_size_ - 1 && table_pitch_[k] < pitch_rad) ++k;
  const double t = (pitch_rad - table_pitch_[k - 1]) / (table_pitch_[k] - table_pitch_[k - 1]);
  return table_dtdb_[k - 1] + t * (table_dtdb_[k] - table_dtdb_[k - 1]);
}

double RotorModel::region2_torque_nm(double speed_rad_s) const {
  if (!(speed_rad_s > 0.0)) return 0.0;
  double torque = k_opt_ * speed_rad_s * speed_rad_s;
  if (min_speed_ > 0.0 && speed_rad_s < min_speed_) {
    const double start = kMinSpeedRampStart * min_speed_;
    const double fraction = (speed_rad_s - start) / (min_speed_ - start);
    torque *= std::clamp(fraction, 0.0, 1.0);
  }
  return std::min(torque, rated_torque_);
}

double RotorModel::generator_torque_nm(const RotorState& state) const {
  if (state.pitch_rad > 0.0) return rated_torque_;  // region 3: constant torque
  const double lower = region2_torque_nm(state.speed_rad_s);
  const double error = state.speed_rad_s - rated_speed_;
  return std::clamp(torque_kp_ * error + state.torque_integral_nm, lower, rated_torque_);
}

RotorState RotorModel::steady_state(double wind_speed_mps) const {
  RotorState s;
  if (!(wind_speed_mps > 0.0) || !std::isfinite(wind_speed_mps)) return s;
  const double r = radius_;
  double speed = wind_.cp_peak().lambda_opt * wind_speed_mps / r;
  if (min_speed_ > 0.0 && speed < min_speed_) {
    // Balance on the ramp below ω_min.
    speed = bisect(
        [&](double w) {
          return wind_.aerodynamic_torque_nm(wind_speed_mps, w, 0.0) - region2_torque_nm(w);
        },
        kMinSpeedRampStart * min_speed_, min_speed_);
  }
  if (speed <= rated_speed_) {
    s.speed_rad_s = speed;
    s.torque_integral_nm = region2_torque_nm(speed) - torque_kp_ * (speed - rated_speed_);
    return s;
  }
  s.speed_rad_s = rated_speed_;
  const double unpitched = wind_.aerodynamic_torque_nm(wind_speed_mps, rated_speed_, 0.0);
  if (unpitched <= rated_torque_) {
    s.torque_integral_nm = unpitched;  // region 2½: T_gen = T_aero at rated speed
    return s;
  }
  s.torque_integral_nm = rated_torque_;
  s.pitch_rad = bisect(
      [&](double beta) {
        return wind_.aerodynamic_torque_nm(wind_speed_mps, rated_speed_, beta) - rated_torque_;
      },
      0.0, p_.max_pitch_rad);
  s.pitch_integral_rad = s.pitch_rad;
  return s;
}

RotorStepOutput RotorModel::step(RotorState& s, double wind_speed_mps, double dt_s) const {
  RotorStepOutput out;
  const double speed = s.speed_rad_s;
  const double error = speed - rated_speed_;
  const double gen = generator_torque_nm(s);

  // Torque loop integrator, clamped with the output (back-calculation, no wind-up).
  if (s.pitch_rad > 0.0) {
    s.torque_integral_nm = rated_torque_ - torque_kp_ * error;
  } else {
    const double lower = region2_torque_nm(speed);
    s.torque_integral_nm =
        std::clamp(s.torque_integral_nm + torque_ki_ * error * dt_s, lower - torque_kp_ * error,
                   rated_torque_ - torque_kp_ * error);
  }

  // Pitch loop: only while the torque is at rated or the blades are pitched.
  double pitch_command = 0.0;
  if (gen >= rated_torque_ || s.pitch_rad > 0.0) {
    const double g = pitch_sensitivity_nm_rad(s.pitch_rad);
    const double wn = p_.loop_natural_frequency_rad_s;
    const double kp = 2.0 * p_.loop_damping_ratio * wn * inertia_ / g;
    const double ki = wn * wn * inertia_ / g;
    s.pitch_integral_rad = std::clamp(s.pitch_integral_rad + ki * error * dt_s, -kp * error,
                                      p_.max_pitch_rad - kp * error);
    pitch_command = std::clamp(kp * error + s.pitch_integral_rad, 0.0, p_.max_pitch_rad);
  } else {
    s.pitch_integral_rad = 0.0;
  }
  const double max_change = p_.max_pitch_rate_rad_s * dt_s;
  s.pitch_rad = s.pitch_rad + std::clamp(pitch_command - s.pitch_rad, -max_change, max_change);

  const double aero = wind_.aerodynamic_torque_nm(wind_speed_mps, speed, s.pitch_rad);
  const double acceleration = (aero - gen) / inertia_;
  s.speed_rad_s = std::max(0.0, speed + acceleration * dt_s);

  out.aero_torque_nm = aero;
  out.generator_torque_nm = gen;
  out.acceleration_rad_s2 = acceleration;
  out.shaft_torque_nm = aero - p_.rotor_inertia_kg_m2 * acceleration;
  out.speed_rad_s = speed;
  out.pitch_rad = s.pitch_rad;
  out.electrical_power_w = wind_.electrical_power_w(gen, speed);
  return out;
}

}  // namespace model::wind
