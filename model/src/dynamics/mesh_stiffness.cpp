#include "model/dynamics/mesh_stiffness.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace model::dynamics {
namespace {
double frac(double v) { return v - std::floor(v); }
}  // namespace

MeshGeometry mesh_geometry(const GearPair& p) {
  MeshGeometry g;
  const double cos_beta = std::cos(p.helix_angle_rad);
  g.transverse_module_m = p.normal_module_m / cos_beta;
  g.transverse_pressure_angle_rad = std::atan(std::tan(p.pressure_angle_rad) / cos_beta);
  const double alpha_t = g.transverse_pressure_angle_rad;
  g.base_helix_angle_rad = std::atan(std::tan(p.helix_angle_rad) * std::cos(alpha_t));
  g.pitch_radius1_m = 0.5 * p.z1 * g.transverse_module_m;
  g.pitch_radius2_m = 0.5 * p.z2 * g.transverse_module_m;
  g.base_radius1_m = g.pitch_radius1_m * std::cos(alpha_t);
  g.base_radius2_m = g.pitch_radius2_m * std::cos(alpha_t);
  // Addendum h_a = m_n (1 + x) (ISO 53 basic rack); an internal gear's tip circle lies inside.
  g.tip_radius1_m = g.pitch_radius1_m + p.normal_module_m * (1.0 + p.x1);
  g.tip_radius2_m = p.internal ? g.pitch_radius2_m - p.normal_module_m * (1.0 - p.x2)
                               : g.pitch_radius2_m + p.normal_module_m * (1.0 + p.x2);
  g.centre_distance_m =
      p.internal ? g.pitch_radius2_m - g.pitch_radius1_m : g.pitch_radius2_m + g.pitch_radius1_m;
  g.base_pitch_m = std::numbers::pi * g.transverse_module_m * std::cos(alpha_t);
  // Path of contact (ISO 21771 §5.4): the line of action between the two tip circles.
  const double t1 =
      std::sqrt(g.tip_radius1_m * g.tip_radius1_m - g.base_radius1_m * g.base_radius1_m);
  const double t2 =
      std::sqrt(g.tip_radius2_m * g.tip_radius2_m - g.base_radius2_m * g.base_radius2_m);
  const double a_sin = g.centre_distance_m * std::sin(alpha_t);
  g.path_of_contact_m = p.internal ? t1 - t2 + a_sin : t1 + t2 - a_sin;
  // Contact starts where gear 2's tip circle cuts the line of action.
  const double r2_sin = g.pitch_radius2_m * std::sin(alpha_t);
  g.pitch_point_m = p.internal ? r2_sin - t2 : t2 - r2_sin;
  g.transverse_contact_ratio = g.path_of_contact_m / g.base_pitch_m;
  g.overlap_ratio =
      p.face_width_m * std::sin(p.helix_angle_rad) / (std::numbers::pi * p.normal_module_m);
  return g;
}

double iso_single_pair_stiffness(const GearPair& p) {
  // ISO 6336-1 §9.3, Table (coefficients C1..C9 of q'), virtual tooth numbers z_n = z / cos³β.
  const double cb3 = std::pow(std::cos(p.helix_angle_rad), 3);
  const double zn1 = p.z1 / cb3;
  const double inv_zn2 = p.internal ? 0.0 : cb3 / p.z2;  // internal gear: z_n2 → ∞
  const double x1 = p.x1;
  const double x2 = p.x2;
  const double q = 0.04723 + 0.15551 / zn1 + 0.25791 * inv_zn2 - 0.00635 * x1 - 0.11654 * x1 / zn1 -
                   0.00193 * x2 - 0.24188 * x2 * inv_zn2 + 0.00529 * x1 * x1 + 0.00182 * x2 * x2;
  const double c_th = 1.0 / q;  // [N/(mm·µm)]
  constexpr double kCm = 0.8;   // theoretical → measured
  constexpr double kCr = 1.0;   // solid gear blanks
  constexpr double kHfpOverMn = 1.25;
  const double alpha_n_deg = p.pressure_angle_rad * 180.0 / std::numbers::pi;
  const double cb = (1.0 + 0.5 * (1.2 - kHfpOverMn)) * (1.0 - 0.02 * (20.0 - alpha_n_deg));
  return c_th * kCm * kCr * cb * std::cos(p.helix_angle_rad);
}

double iso_mesh_stiffness(const GearPair& p) {
  const MeshGeometry g = mesh_geometry(p);
  return iso_single_pair_stiffness(p) * (0.75 * g.transverse_contact_ratio + 0.25);
}

double contact_line_length_m(const MeshGeometry& g, double b, double cycles, double relief) {
  // Plane of action: s along the path of contact [0, g_α], y across the face [0, b].
  // A contact line is inclined by β_b: s(y) = s_j + y·tan β_b, and the pairs follow
  // each other at one base pitch.
  const double tb = std::tan(g.base_helix_angle_rad);
  const double cb = std::cos(g.base_helix_angle_rad);
  const double p = g.base_pitch_m;
  const double ga = g.path_of_contact_m;
  // Tip relief: weight w(s) = min(1, s/L, (g_α − s)/L) with L = relief·(g_α − p_bt) (≤ g_α/2),
  // and W(s) = ∫_0^s w its integral (piecewise quadratic), so that a helical contact line's
  // weighted length is (W(s_hi) − W(s_lo)) / (tan β_b · cos β_b).
  const double ramp = std::min(std::clamp(relief, 0.0, 1.0) * std::max(0.0, ga - p), 0.5 * ga);
  const auto weight = [&](double s) {
    if (s < 0.0 || s >= ga) return 0.0;
    if (ramp <= 0.0) return 1.0;
    return std::min({1.0, s / ramp, (ga - s) / ramp});
  };
  const auto integral = [&](double s) {
    s = std::clamp(s, 0.0, ga);
    if (ramp <= 0.0) return s;
    if (s < ramp) return s * s / (2.0 * ramp);
    if (s < ga - ramp) return 0.5 * ramp + (s - ramp);
    const double u = s - (ga - ramp);
    return 0.5 * ramp + (ga - 2.0 * ramp) + u - u * u / (2.0 * ramp);
  };
  const double s0 = g.pitch_point_m - 0.5 * b * tb + cycles * p;  // reference pair at y = 0
  const int j_lo = static_cast<int>(std::floor((-b * tb - s0) / p)) - 1;
  const int j_hi = static_cast<int>(std::ceil((ga - s0) / p)) + 1;
  double total = 0.0;
  for (int j = j_lo; j <= j_hi; ++j) {
    const double sj = s0 + j * p;
    if (tb == 0.0) {
      total += b * weight(sj);
      continue;
    }
    const double y_lo = std::max(0.0, -sj / tb);
    const double y_hi = std::min(b, (ga - sj) / tb);
    if (y_hi > y_lo) total += (integral(sj + y_hi * tb) - integral(sj + y_lo * tb)) / (tb * cb);
  }
  return total;
}

MeshStiffness mesh_stiffness(const GearPair& pair, double scale, double relief) {
  const MeshGeometry g = mesh_geometry(pair);
  MeshStiffness k;
  // c_γα [N/(mm·µm)] · b [mm] = [N/µm]; ×1e6 → [N/m] in the transverse plane.
  const double transverse_n_m = iso_mesh_stiffness(pair) * pair.face_width_m * 1e3 * 1e6;
  const double cbb = std::cos(g.base_helix_angle_rad);
  k.mean_n_m = scale * transverse_n_m / (cbb * cbb);
  double sum = 0.0;
  for (std::size_t i = 0; i < PeriodicTable::kSize; ++i) {
    const double tau = static_cast<double>(i) / static_cast<double>(PeriodicTable::kSize);
    k.shape.values[i] = contact_line_length_m(g, pair.face_width_m, tau, relief);
    sum += k.shape.values[i];
  }
  const double mean = sum / static_cast<double>(PeriodicTable::kSize);
  for (double& v : k.shape.values) v /= mean;
  return k;
}

double sun_planet_phase(int z_sun, double psi_rad) {
  return frac(z_sun * psi_rad / (2.0 * std::numbers::pi));
}

double ring_planet_phase(int z_ring, double psi_rad) {
  return frac(-z_ring * psi_rad / (2.0 * std::numbers::pi));
}

double ring_sun_phase(int z_planet) { return frac(0.5 * (z_planet - 1)); }

}  // namespace model::dynamics

namespace model::dynamics {

double iso1328_profile_form_tolerance_um(double normal_module_m, double reference_diameter_m,
                                         int grade) {
  const double m_mm = normal_module_m * 1e3;
  const double d_mm = reference_diameter_m * 1e3;
  const double grade5 = 2.5 * std::sqrt(m_mm) + 0.17 * std::sqrt(d_mm) + 0.5;
  return grade5 * std::pow(std::sqrt(2.0), grade - 5);
}

double transmission_error_prior_m(const GearPair& pair, int grade, int harmonic) {
  if (harmonic < 1) return 0.0;
  const MeshGeometry g = mesh_geometry(pair);
  const double cos_beta = std::cos(pair.helix_angle_rad);
  const double d1 = pair.z1 * pair.normal_module_m / cos_beta;
  const double d2 = pair.z2 * pair.normal_module_m / cos_beta;
  const double f1 = iso1328_profile_form_tolerance_um(pair.normal_module_m, d1, grade);
  const double f2 = iso1328_profile_form_tolerance_um(pair.normal_module_m, d2, grade);
  const double f_pair_m = std::sqrt(f1 * f1 + f2 * f2) * 1e-6;
  const double h = harmonic;
  const double helical =
      g.overlap_ratio > 0.0 ? std::min(1.0, 1.0 / (std::numbers::pi * h * g.overlap_ratio)) : 1.0;
  return 0.25 * f_pair_m / h * helical;
}

PeriodicTable transmission_error_table(const double* amplitudes_m, std::size_t count,
                                       const double* phases_rad) {
  PeriodicTable t = PeriodicTable::constant(0.0);
  for (std::size_t i = 0; i < PeriodicTable::kSize; ++i) {
    const double x = static_cast<double>(i) / static_cast<double>(PeriodicTable::kSize);
    double e = 0.0;
    for (std::size_t h = 1; h <= count; ++h)
      e += amplitudes_m[h - 1] * std::cos(2.0 * std::numbers::pi * static_cast<double>(h) * x +
                                          (phases_rad ? phases_rad[h - 1] : 0.0));
    t.values[i] = e;
  }
  return t;
}

}  // namespace model::dynamics
