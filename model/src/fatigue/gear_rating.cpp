// ISO 6336-1/-2/-3 (2006 editions) and ISO 21771 geometry. Equation numbers refer
// to those editions.
#include "model/fatigue/gear_rating.hpp"

#include "units.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace model::fatigue {
namespace {
constexpr double kPi = std::numbers::pi;

constexpr double kFshConstant = 0.023;    // [µm·mm/N] ISO 6336-1 method C, f_sh
constexpr double kMinLineLoadNmm = 1e-6;  // [N/mm] floor of F_m/b in K_Hβ

double involute(double a) { return std::tan(a) - a; }

// Inverse involute by Newton's method (inv' = tan²).
double inverse_involute(double inv) {
  double a = std::cbrt(3.0 * inv);  // series start: inv ≈ a³/3
  for (int i = 0; i < 30; ++i) {
    const double t = std::tan(a);
    const double step = (involute(a) - inv) / (t * t);
    a -= step;
    if (std::abs(step) < 1e-15) break;
  }
  return a;
}
double sign(double v) { return v < 0.0 ? -1.0 : 1.0; }
}  // namespace

PairGeometry pair_geometry(double z1, double z2, double x1, double x2, double m_n_m,
                           double alpha_n_rad, double beta_rad, double b_m, const BasicRack& rack) {
  PairGeometry g;
  g.z[0] = z1;
  g.z[1] = z2;
  g.x[0] = x1;
  g.x[1] = x2;
  g.m_n_m = m_n_m;
  g.alpha_n_rad = alpha_n_rad;
  g.beta_rad = beta_rad;
  g.b_m = b_m;
  g.internal = z2 < 0.0;
  const double m_t = m_n_m / std::cos(beta_rad);                          // ISO 21771 eq. 5
  g.alpha_t_rad = std::atan(std::tan(alpha_n_rad) / std::cos(beta_rad));  // eq. 9
  g.beta_b_rad = std::asin(std::sin(beta_rad) * std::cos(alpha_n_rad));   // eq. 13
  for (int i = 0; i < 2; ++i) {
    g.d_m[i] = g.z[i] * m_t;                                        // eq. 7
    g.db_m[i] = g.d_m[i] * std::cos(g.alpha_t_rad);                 // eq. 11
    g.da_m[i] = g.d_m[i] + 2.0 * m_n_m * (rack.addendum + g.x[i]);  // eq. 19 (signed)
  }
  // Working pressure angle: inv α_wt = inv α_t + 2·tan α_n·(x1+x2)/(z1+z2) (ISO 21771 eq. 38).
  g.alpha_wt_rad = inverse_involute(involute(g.alpha_t_rad) +
                                    2.0 * std::tan(alpha_n_rad) * (x1 + x2) / (z1 + z2));
  g.a_w_m = (g.db_m[0] + g.db_m[1]) / (2.0 * std::cos(g.alpha_wt_rad));  // eq. 40 (signed)
  // Length of path of contact (ISO 21771 eq. 69, signed form covers internal pairs).
  const double g_alpha =
      0.5 * (std::sqrt(g.da_m[0] * g.da_m[0] - g.db_m[0] * g.db_m[0]) +
             sign(z2) * std::sqrt(g.da_m[1] * g.da_m[1] - g.db_m[1] * g.db_m[1])) -
      g.a_w_m * std::sin(g.alpha_wt_rad);
  g.eps_alpha = g_alpha / (kPi * m_t * std::cos(g.alpha_t_rad));  // eq. 72
  g.eps_beta = b_m * std::sin(beta_rad) / (kPi * m_n_m);          // eq. 74
  g.u = z2 / z1;
  return g;
}

std::optional<BendingFormFactors> bending_form_factors(const PairGeometry& p, int gear,
                                                       const BasicRack& rack) {
  const double z = p.z[gear];
  if (z < 0.0) return std::nullopt;
  const double x = p.x[gear];
  const double m_n = p.m_n_m;
  const double an = p.alpha_n_rad;
  const double cb = std::cos(p.beta_b_rad);
  const double z_n = z / (cb * cb * std::cos(p.beta_rad));  // ISO 6336-3 eq. 34
  const double h_fp = rack.dedendum * m_n;
  const double rho_fp = rack.root_radius * m_n;
  // eq. 35–37 (no protuberance: s_pr = 0); T = π/3 for external gears.
  const double e =
      kPi / 4.0 * m_n - h_fp * std::tan(an) - (1.0 - std::sin(an)) * rho_fp / std::cos(an);
  const double g_param = rho_fp / m_n - h_fp / m_n + x;
  const double h = 2.0 / z_n * (kPi / 2.0 - e / m_n) - kPi / 3.0;
  // eq. 38: θ = 2G/z_n·tan θ − H, fixed-point iteration from π/6 (converges in a few steps).
  double theta = kPi / 6.0;
  for (int i = 0; i < 50; ++i) {
    const double next = 2.0 * g_param / z_n * std::tan(theta) - h;
    if (std::abs(next - theta) < 1e-14) {
      theta = next;
      break;
    }
    theta = next;
  }
  BendingFormFactors f;
  const double s_fn =
      m_n * (z_n * std::sin(kPi / 3.0 - theta) +
             std::sqrt(3.0) * (g_param / std::cos(theta) - rho_fp / m_n));  // eq. 39
  const double ct = std::cos(theta);
  const double rho_f = m_n * (rho_fp / m_n + 2.0 * g_param * g_param /
                                                 (ct * (z_n * ct * ct - 2.0 * g_param)));  // eq. 40
  // Outer point of single pair contact in the virtual spur gear, eq. 42–47.
  const double eps_an = p.eps_alpha / (cb * cb);
  const double d_n = m_n * z_n;
  const double d_bn = d_n * std::cos(an);
  const double d_an = d_n + p.da_m[gear] - p.d_m[gear];
  const double p_bn = kPi * m_n * std::cos(an);
  const double root = std::sqrt(d_an * d_an / 4.0 - d_bn * d_bn / 4.0) - p_bn * (eps_an - 1.0);
  const double d_en = 2.0 * std::sqrt(root * root + d_bn * d_bn / 4.0);
  const double alpha_en = std::acos(d_bn / d_en);
  const double gamma_e =
      (0.5 * kPi + 2.0 * x * std::tan(an)) / z_n + involute(an) - involute(alpha_en);
  const double alpha_fen = alpha_en - gamma_e;
  const double h_fe = 0.5 * m_n *
                      ((std::cos(gamma_e) - std::sin(gamma_e) * std::tan(alpha_fen)) * d_en / m_n -
                       z_n * std::cos(kPi / 3.0 - theta) - g_param / ct + rho_fp / m_n);  // eq. 41
  f.s_fn_m = s_fn;
  f.rho_f_m = rho_f;
  f.h_fe_m = h_fe;
  f.alpha_fen_rad = alpha_fen;
  f.y_f = (6.0 * h_fe / m_n * std::cos(alpha_fen)) /
          ((s_fn / m_n) * (s_fn / m_n) * std::cos(an));  // eq. 33
  const double l = s_fn / h_fe;
  const double q_s = s_fn / (2.0 * rho_f);
  f.y_s = (1.2 + 0.13 * l) * std::pow(q_s, 1.0 / (1.21 + 2.3 / l));  // eq. 45
  return f;
}

const char* lead_modification_name(LeadModification m) {
  switch (m) {
    case LeadModification::kNone:
      return "none";
    case LeadModification::kHelixCorrection:
      return "helix";
    case LeadModification::kHelixCorrectionAndCrowning:
      return "helix-crowning";
    case LeadModification::kCrowning:
      return "crowning";
    case LeadModification::kEndRelief:
      return "end-relief";
  }
  return "?";
}

std::optional<LeadModification> parse_lead_modification(std::string_view name) {
  for (auto m : {LeadModification::kNone, LeadModification::kHelixCorrection,
                 LeadModification::kHelixCorrectionAndCrowning, LeadModification::kCrowning,
                 LeadModification::kEndRelief}) {
    if (name == lead_modification_name(m)) return m;
  }
  return std::nullopt;
}

double PinionShaft::gamma(double d1_m, double b_m) const {
  // ISO 6336-1:2006 method C, f_sh of a pinion (see the header): lengths in any one unit.
  double bending = 0.0;
  if (shaft_diameter_m > 0.0 && k_prime != 0.0) {
    const double r = d1_m / shaft_diameter_m;
    bending = k_prime * bearing_span_m * offset_m / (d1_m * d1_m) * r * r * r * r;
  }
  const double bd = b_m / d1_m;
  return (std::abs(torsion_meshes + bending - 0.3) + 0.3) * bd * bd;
}

MeshRating mesh_rating(const PairGeometry& p, const Material& m1, const Material& m2, double k_a,
                       const RatingSettings& s, const PinionShaft& pinion) {
  MeshRating r;
  r.geometry = p;
  const double cbb = std::cos(p.beta_b_rad);
  const double cat = std::cos(p.alpha_t_rad);
  // ISO 6336-2:2006 eq. 9: zone factor.
  r.z_h = std::sqrt(2.0 * cbb * std::cos(p.alpha_wt_rad) / (cat * cat * std::sin(p.alpha_wt_rad)));
  // eq. 22: elasticity factor, E in N/mm² so that Z_E is in √(N/mm²).
  const double e1 = m1.youngs_modulus_pa * 1e-6, e2 = m2.youngs_modulus_pa * 1e-6;
  r.z_e_sqrt_mpa = std::sqrt(1.0 / (kPi * ((1.0 - m1.poisson_ratio * m1.poisson_ratio) / e1 +
                                           (1.0 - m2.poisson_ratio * m2.poisson_ratio) / e2)));
  // eq. 34–36: contact ratio factor.
  const double ea = p.eps_alpha, eb = p.eps_beta;
  r.z_eps = eb < 1.0 ? std::sqrt((4.0 - ea) / 3.0 * (1.0 - eb) + eb / ea) : std::sqrt(1.0 / ea);
  // §9 helix angle factor: Z_β = 1/√cos β in ISO 6336-2:2006 (as corrected, and eq. 29 of the
  // 2019 edition). √cos β is the older DIN 3990 / ISO 6336-2:1996 form; it gave 1.5 % less
  // stress on 10° helical gears, which beyond the knee (exponent 2m − 1 = 33) is 40 % less damage.
  r.z_beta = 1.0 / std::sqrt(std::cos(p.beta_rad));
  // eq. 10–13: single pair tooth contact factors.
  if (!p.internal) {
    const double t1 = std::sqrt(p.da_m[0] * p.da_m[0] / (p.db_m[0] * p.db_m[0]) - 1.0);
    const double t2 = std::sqrt(p.da_m[1] * p.da_m[1] / (p.db_m[1] * p.db_m[1]) - 1.0);
    const double m_1 = std::tan(p.alpha_wt_rad) / std::sqrt((t1 - 2.0 * kPi / p.z[0]) *
                                                            (t2 - (ea - 1.0) * 2.0 * kPi / p.z[1]));
    const double m_2 = std::tan(p.alpha_wt_rad) / std::sqrt((t2 - 2.0 * kPi / p.z[1]) *
                                                            (t1 - (ea - 1.0) * 2.0 * kPi / p.z[0]));
    auto factor = [eb](double m) {
      if (eb >= 1.0) return 1.0;
      return std::max(1.0, m - eb * (m - 1.0));
    };
    r.z_b = factor(m_1);
    r.z_d = factor(m_2);
  }
  r.k_a = k_a;
  r.k_v = 1.0;
  // ISO 6336-1:2006 eq. 73–74: K_Fβ = K_Hβ^N_F, b/h the smaller of the pair, not below 3.
  const double h_tooth = (s.rack.addendum + s.rack.dedendum) * p.m_n_m;
  const double bh = std::max(3.0, p.b_m / h_tooth);
  r.n_f = bh * bh / (1.0 + bh + bh * bh);
  // K_Hβ inputs, ISO 6336-1:2006 method C (§7.5). Lengths in mm, µm as the standard writes them.
  r.k_h_beta_fixed = s.k_h_beta_override;
  const double b_mm = p.b_m * kMm;
  r.f_sh_per_line_load = kFshConstant * pinion.gamma(std::abs(p.d_m[0]), p.b_m);
  // Helix slope tolerance, ISO 1328-1:2013 §5.3 (= 1995 edition f_Hβ): grade 5 value
  // (0.07·√d + 0.45·√b + 3) µm, d and b in mm, times √2 per grade; the larger gear's d.
  const double d_big_mm = std::max(std::abs(p.d_m[0]), std::abs(p.d_m[1])) * kMm;
  r.f_h_beta5_um = 0.07 * std::sqrt(d_big_mm) + 0.45 * std::sqrt(b_mm) + 3.0;
  r.f_h_beta_um = r.f_h_beta5_um * std::pow(std::sqrt(2.0), s.accuracy_grade - 5);
  r.contact_pattern_verified = s.face_load.contact_pattern_verified;
  r.f_ma_um = s.face_load.f_ma_factor * r.f_h_beta_um;
  switch (s.face_load.lead) {
    case LeadModification::kNone:
      r.b1 = 1.0;
      r.b2 = 1.0;
      break;
    case LeadModification::kHelixCorrection:
      r.b1 = 0.1;
      r.b2 = 1.0;
      break;
    case LeadModification::kHelixCorrectionAndCrowning:
      r.b1 = 0.1;
      r.b2 = 0.5;
      break;
    case LeadModification::kCrowning:
      r.b1 = 0.5;
      r.b2 = 0.5;
      break;
    case LeadModification::kEndRelief:
      r.b1 = 0.7;
      r.b2 = 0.7;
      break;
  }
  r.c_gamma_beta = 0.85 * s.c_gamma_n_mm_um;  // ISO 6336-1:2006 §9: c_γβ = 0.85·c_γα
  if (s.face_load.case_hardened) {
    r.y_beta_factor = 0.15;  // case-hardened or nitrided: y_β = 0.15·F_βx, y_β ≤ 6 µm
    r.y_beta_max_um = 6.0;
  } else {
    r.y_beta_factor =
        320.0 / std::min(m1.sigma_hlim_mpa, m2.sigma_hlim_mpa);  // y_β = 320/σ_Hlim·F_βx
    r.y_beta_max_um = std::numeric_limits<double>::infinity();
  }
  // ISO 6336-3:2006 eq. 47: helix angle factor, ε_β ≤ 1 and β ≤ 30° in the formula.
  const double beta_deg = std::min(30.0, p.beta_rad * 180.0 / kPi);
  r.y_beta = 1.0 - std::min(1.0, eb) * beta_deg / 120.0;
  for (int i = 0; i < 2; ++i) {
    if (auto f = bending_form_factors(p, i, s.rack)) {
      r.bending[i] = *f;
      r.bending_rated[i] = true;
    }
  }
  // K_Hα inputs: ISO 1328-1:2013 single pitch tolerance f_pT = (0.001·d + 0.4·m_n + 5)·√2^(A−5) µm
  // (d, m_n in mm), of the larger gear; f_pb = f_pt·cos α_t; y_α = 0.075·f_pb for
  // case-hardened steel (ISO 6336-1:2006 eq. 77).
  const double f_pt_um = (0.001 * d_big_mm + 0.4 * p.m_n_m * kMm + 5.0) *
                         std::pow(std::sqrt(2.0), s.accuracy_grade - 5);
  const double f_pb_um = f_pt_um * cat;
  const double y_alpha_um = std::min(3.0, 0.075 * f_pb_um);
  r.k_alpha_term_n_mm = s.c_gamma_n_mm_um * (f_pb_um - y_alpha_um);
  r.eps_gamma = ea + eb;
  r.k_h_alpha_max = r.eps_gamma / (ea * r.z_eps * r.z_eps);  // eq. 76
  r.k_f_alpha_max = r.eps_gamma / (0.25 * ea + 0.75);        // eq. 78
  return r;
}

FaceLoad MeshRating::face_load(double ft_n) const {
  FaceLoad f;
  const double b_mm = geometry.b_m * kMm;
  // F_m = F_t·K_A·K_v (ISO 6336-1:2006 §7.5); a floor keeps K_Hβ finite at zero load
  // (its √ branch grows as (F_m/b)^-½, so F_t·K_Hβ → 0 and the stress still vanishes).
  f.line_load_n_mm = std::max(kMinLineLoadNmm, std::abs(ft_n) * k_a * k_v / b_mm);
  if (k_h_beta_fixed > 0.0) {
    f.k_h_beta = k_h_beta_fixed;
  } else {
    f.f_sh_um = f_sh_per_line_load * f.line_load_n_mm;
    // ISO 6336-1:2006 §7.5.2.3: F_βx = 1.33·B1·f_sh + B2·f_ma (eq. 52, contact pattern not
    // proven), or with a verified favourable contact pattern F_βx = 1.33·B1·f_sh − f_Hβ5
    // (eq. 53 as replaced by ISO 6336-1:2006/Cor.1:2008); either not below
    // F_βx,min = max(0.005·F_m/b, 0.5·f_Hβ).
    const double fbx_min = std::max(0.005 * f.line_load_n_mm, 0.5 * f_h_beta_um);
    const double fbx = contact_pattern_verified ? 1.33 * b1 * f.f_sh_um - f_h_beta5_um
                                                : 1.33 * b1 * f.f_sh_um + b2 * f_ma_um;
    f.f_beta_x_um = std::max(fbx_min, fbx);
    f.y_beta_um = std::min(y_beta_factor * f.f_beta_x_um, y_beta_max_um);  // running-in allowance
    f.f_beta_y_um = f.f_beta_x_um - f.y_beta_um;
    // K_Hβ = 1 + c_γβ·F_βy/(2·F_m/b) while that is ≤ 2, else √(2·c_γβ·F_βy/(F_m/b)).
    const double k = 1.0 + c_gamma_beta * f.f_beta_y_um / (2.0 * f.line_load_n_mm);
    f.k_h_beta = k <= 2.0 ? k : std::sqrt(2.0 * c_gamma_beta * f.f_beta_y_um / f.line_load_n_mm);
  }
  f.k_f_beta = std::pow(f.k_h_beta, n_f);  // ISO 6336-1:2006 eq. 73
  return f;
}

double MeshRating::k_alpha(double ft_n) const { return k_alpha_at(ft_n, face_load(ft_n).k_h_beta); }

double MeshRating::k_alpha_at(double ft_n, double k_h_beta) const {
  const double b_mm = geometry.b_m * kMm;
  const double fth_per_b = std::max(1e-9, std::abs(ft_n) * k_a * k_v * k_h_beta / b_mm);  // [N/mm]
  double k;
  if (eps_gamma <= 2.0) {
    k = eps_gamma / 2.0 * (0.9 + 0.4 * k_alpha_term_n_mm / fth_per_b);  // eq. 75
  } else {
    k = 0.9 + 0.4 * std::sqrt(2.0 * (eps_gamma - 1.0) / eps_gamma) * k_alpha_term_n_mm /
                  fth_per_b;  // eq. 76
  }
  return std::max(1.0, k);
}

double MeshRating::contact_stress_nominal_mpa(double ft_n) const {
  const double d1_mm = std::abs(geometry.d_m[0]) * kMm;
  const double b_mm = geometry.b_m * kMm;
  const double u = geometry.u;
  return z_h * z_e_sqrt_mpa * z_eps * z_beta *
         std::sqrt(std::abs(ft_n) / (d1_mm * b_mm) * (u + 1.0) / u);
}

double MeshRating::contact_stress_mpa(double ft_n, int gear) const {
  const double k_ha = std::min(k_alpha(ft_n), std::max(1.0, k_h_alpha_max));
  const double z = gear == 0 ? z_b : z_d;
  return z * contact_stress_nominal_mpa(ft_n) *
         std::sqrt(k_a * k_v * face_load(ft_n).k_h_beta * k_ha);
}

double MeshRating::bending_stress_mpa(double ft_n, int gear) const {
  if (!bending_rated[gear]) return 0.0;
  const double k_fa = std::min(k_alpha(ft_n), std::max(1.0, k_f_alpha_max));
  const double b_mm = geometry.b_m * kMm;
  const double m_mm = geometry.m_n_m * kMm;
  const BendingFormFactors& f = bending[gear];
  // σ_F = F_t/(b·m_n)·Y_F·Y_S·Y_β·Y_B·Y_DT·K_A·K_v·K_Fβ·K_Fα, Y_B = Y_DT = 1.
  return std::abs(ft_n) / (b_mm * m_mm) * f.y_f * f.y_s * y_beta * k_a * k_v *
         face_load(ft_n).k_f_beta * k_fa;
}

MeshStresses MeshRating::stresses(double ft_n) const {
  // The arithmetic of contact_stress_mpa() and bending_stress_mpa(), operation for operation.
  const FaceLoad fl = face_load(ft_n);
  const double k = k_alpha_at(ft_n, fl.k_h_beta);
  MeshStresses s;
  const double k_ha = std::min(k, std::max(1.0, k_h_alpha_max));
  const double nominal = contact_stress_nominal_mpa(ft_n);
  const double root = std::sqrt(k_a * k_v * fl.k_h_beta * k_ha);
  s.contact_mpa[0] = z_b * nominal * root;
  s.contact_mpa[1] = z_d * nominal * root;
  const double k_fa = std::min(k, std::max(1.0, k_f_alpha_max));
  const double b_mm = geometry.b_m * kMm;
  const double m_mm = geometry.m_n_m * kMm;
  for (int g = 0; g < 2; ++g) {
    if (!bending_rated[g]) continue;
    const BendingFormFactors& f = bending[g];
    s.bending_mpa[g] =
        std::abs(ft_n) / (b_mm * m_mm) * f.y_f * f.y_s * y_beta * k_a * k_v * fl.k_f_beta * k_fa;
  }
  return s;
}

}  // namespace model::fatigue
