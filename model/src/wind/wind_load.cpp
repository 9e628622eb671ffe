#include "model/wind/wind_load.hpp"

#include "units.hpp"

#include <algorithm>
#include <cmath>

#include "model/wind/corrections.hpp"

namespace model::wind {
namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

const char* region_name(OperatingRegion region) {
  switch (region) {
    case OperatingRegion::kBelowCutIn:
      return "below_cut_in";
    case OperatingRegion::kTracking:
      return "2";
    case OperatingRegion::kSpeedLimited:
      return "2.5";
    case OperatingRegion::kRated:
      return "3";
    case OperatingRegion::kAboveCutOut:
      return "above_cut_out";
    case OperatingRegion::kStopped:
      return "stopped";
  }
  return "?";
}

WindLoad::WindLoad(const Turbine& turbine)
    : turbine_(turbine),
      peak_(find_cp_peak(turbine.cp)),
      rated_speed_rad_s_(turbine.rated_rotor_speed_rpm * kRpmToRadS),
      min_speed_rad_s_(turbine.min_rotor_speed_rpm * kRpmToRadS),
      rated_torque_nm_(turbine.rated_torque_nm),
      half_rho_area_(0.5 * turbine.air_density_kg_m3 * kPi * turbine.rotor_radius_m *
                     turbine.rotor_radius_m) {
  tracking_lambda_ = turbine.corrections.tracking_tip_speed_ratio > 0.0
                         ? turbine.corrections.tracking_tip_speed_ratio
                         : peak_.lambda_opt;
  speed_limit_wind_mps_ = tracking_lambda_ > 0.0
                              ? rated_speed_rad_s_ * turbine_.rotor_radius_m / tracking_lambda_
                              : 0.0;
  double speed = 0.0;
  torque_at_speed_limit_nm_ = tracking_torque_nm(speed_limit_wind_mps_, &speed);
}

double WindLoad::aerodynamic_torque_nm(double wind_speed_mps, double rotor_speed_rad_s,
                                       double pitch_rad) const {
  if (!(wind_speed_mps > 0.0) || !(rotor_speed_rad_s > 0.0)) return 0.0;
  const double lambda = rotor_speed_rad_s * turbine_.rotor_radius_m / wind_speed_mps;
  const double cp = power_coefficient(turbine_.cp, lambda, pitch_rad);
  // P = ½ρπR²v³·Cp (actuator disc), T = P/ω
  return half_rho_area_ * wind_speed_mps * wind_speed_mps * wind_speed_mps * cp / rotor_speed_rad_s;
}

double WindLoad::tracking_torque_nm(double wind_speed_mps, double* speed_rad_s) const {
  // Region 2: ω = λ_opt·v/R within the controller's speed range.
  double speed = tracking_lambda_ * wind_speed_mps / turbine_.rotor_radius_m;
  speed = std::clamp(speed, min_speed_rad_s_, std::max(min_speed_rad_s_, rated_speed_rad_s_));
  *speed_rad_s = speed;
  return std::min(aerodynamic_torque_nm(wind_speed_mps, speed, 0.0), rated_torque_nm_);
}

double WindLoad::effective_cp(double torque_nm, double speed_rad_s, double wind_speed_mps) const {
  const double available = half_rho_area_ * wind_speed_mps * wind_speed_mps * wind_speed_mps;
  return available > 0.0 ? torque_nm * speed_rad_s / available : 0.0;
}

OperatingRegion WindLoad::region_of(double wind_speed_mps) const {
  if (!(wind_speed_mps >= turbine_.cut_in_wind_mps)) return OperatingRegion::kBelowCutIn;
  if (wind_speed_mps >= turbine_.cut_out_wind_mps) return OperatingRegion::kAboveCutOut;
  if (wind_speed_mps >= turbine_.rated_wind_mps) return OperatingRegion::kRated;
  if (wind_speed_mps >= speed_limit_wind_mps_) return OperatingRegion::kSpeedLimited;
  return OperatingRegion::kTracking;
}

WindLoadOutput WindLoad::steady_state(double wind_speed_mps) const {
  WindLoadOutput out;
  out.region = region_of(wind_speed_mps);
  switch (out.region) {
    case OperatingRegion::kBelowCutIn:
    case OperatingRegion::kAboveCutOut:
    case OperatingRegion::kStopped:
      return out;
    case OperatingRegion::kTracking:
      out.torque_nm = tracking_torque_nm(wind_speed_mps, &out.rotor_speed_rad_s);
      break;
    case OperatingRegion::kSpeedLimited: {
      // Region 2½ ramp (see header: joins T(v_sl) to T_rated at v_rated).
      const double span = turbine_.rated_wind_mps - speed_limit_wind_mps_;
      const double fraction = span > 0.0 ? (wind_speed_mps - speed_limit_wind_mps_) / span : 1.0;
      out.rotor_speed_rad_s = rated_speed_rad_s_;
      out.torque_nm =
          torque_at_speed_limit_nm_ + (rated_torque_nm_ - torque_at_speed_limit_nm_) * fraction;
      break;
    }
    case OperatingRegion::kRated:
      out.rotor_speed_rad_s = rated_speed_rad_s_;
      out.torque_nm = rated_torque_nm_;
      break;
  }
  out.tip_speed_ratio = out.rotor_speed_rad_s * turbine_.rotor_radius_m / wind_speed_mps;
  out.power_coefficient = effective_cp(out.torque_nm, out.rotor_speed_rad_s, wind_speed_mps);
  return out;
}

WindLoadOutput WindLoad::with_rotor_speed(double wind_speed_mps, double rotor_speed_rad_s,
                                          double pitch_rad, bool has_pitch) const {
  return with_rotor_speed(wind_speed_mps, rotor_speed_rad_s, pitch_rad, has_pitch, Inflow{});
}

double WindLoad::electrical_power_w(double rotor_torque_nm, double rotor_speed_rad_s) const {
  return model::wind::electrical_power_w(rotor_torque_nm * rotor_speed_rad_s,
                                         turbine_.drivetrain_efficiency,
                                         turbine_.corrections.no_load_loss_w);
}

WindLoadOutput WindLoad::with_rotor_speed(double wind_speed_mps, double rotor_speed_rad_s,
                                          double pitch_rad, bool has_pitch,
                                          const Inflow& inflow) const {
  WindLoadOutput out;
  out.region = region_of(wind_speed_mps);
  out.rotor_speed_rad_s = rotor_speed_rad_s;
  if (out.region == OperatingRegion::kBelowCutIn || out.region == OperatingRegion::kAboveCutOut) {
    return out;
  }
  if (!(rotor_speed_rad_s >= kStoppedRotorSpeedRadS)) {
    out.region = OperatingRegion::kStopped;
    return out;
  }
  const TurbineCorrections& k = turbine_.corrections;
  double free_wind_mps =
      free_stream_wind_mps(wind_speed_mps, k.nacelle_wind_gain, k.nacelle_wind_offset_mps);
  if (k.tracking_band_margin > 0.0 && tracking_lambda_ > 0.0) {
    // Between its speed limits the controller holds its tip-speed ratio λ_c, so the measured
    // speed gives the rotor-effective wind ωR/λ_c; at a limit the speed is held and says nothing
    // about the wind. A 10-minute mean near a limit mixes both: the weight rises linearly from 0 at
    // the limit to 1 at (1 + m)·ω_min and (1 − m)·ω_rated.
    const double m = k.tracking_band_margin;
    const double lo = min_speed_rad_s_, hi = rated_speed_rad_s_;
    const double w_lo = lo > 0.0 ? std::clamp((rotor_speed_rad_s - lo) / (m * lo), 0.0, 1.0) : 1.0;
    const double w_hi = std::clamp((hi - rotor_speed_rad_s) / (m * hi), 0.0, 1.0);
    const double w = w_lo * w_hi;
    const double tracking_wind = rotor_speed_rad_s * turbine_.rotor_radius_m / tracking_lambda_;
    free_wind_mps = w * tracking_wind + (1.0 - w) * free_wind_mps;
  }
  out.tip_speed_ratio =
      free_wind_mps > 0.0 ? rotor_speed_rad_s * turbine_.rotor_radius_m / free_wind_mps : 0.0;
  if (out.region == OperatingRegion::kRated && !has_pitch) {
    out.torque_nm = rated_torque_nm_;
  } else {
    const bool own_density = inflow.air_density_kg_m3 > 0.0;  // false for NaN too
    const double density_scale =
        own_density ? inflow.air_density_kg_m3 / turbine_.air_density_kg_m3 : 1.0;
    const double yaw_scale = k.yaw_loss_exponent > 0.0
                                 ? yaw_power_factor(inflow.yaw_error_rad, k.yaw_loss_exponent)
                                 : 1.0;
    const double scale = density_scale * yaw_scale;
    const double beta = has_pitch ? pitch_rad : 0.0;
    auto capped = [&](double v) {
      return std::min(scale * aerodynamic_torque_nm(v, rotor_speed_rad_s, beta), rated_torque_nm_);
    };
    const double intensity = std::fabs(k.turbulence_intensity);
    if (intensity > 0.0) {
      // The 10-minute mean of the torque over a Gaussian wind v(1 + I·ξ) at the measured mean
      // speed: 5-point Gauss–Hermite quadrature (probabilists' nodes; weights sum to 1).
      static constexpr double kNode[5] = {-2.8569700138728056, -1.3556261799742659, 0.0,
                                          1.3556261799742659, 2.8569700138728056};
      static constexpr double kWeight[5] = {0.011257411327720691, 0.22207592200561265,
                                            0.53333333333333333, 0.22207592200561265,
                                            0.011257411327720691};
      double mean = 0.0;
      for (int i = 0; i < 5; ++i) {
        mean += kWeight[i] * capped(std::max(0.0, free_wind_mps * (1.0 + intensity * kNode[i])));
      }
      out.torque_nm = mean;
    } else {
      out.torque_nm = capped(free_wind_mps);
    }
  }
  out.power_coefficient = effective_cp(out.torque_nm, rotor_speed_rad_s, free_wind_mps);
  return out;
}

}  // namespace model::wind
