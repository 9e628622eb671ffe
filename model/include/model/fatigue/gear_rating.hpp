#pragma once
// Gear-mesh load capacity per ISO 6336 (2006 editions): the contact stress of
// ISO 6336-2 (method B) and the tooth-root stress of ISO 6336-3 (method B) as
// functions of the transverse tangential force F_t at the reference circle, with
// every geometry factor computed from the drivetrain description.
//
// Factors and where they come from (see mesh_rating() for the equations):
//   Z_H, Z_E, Z_ε, Z_β, Z_B/Z_D, Y_F, Y_S, Y_β, K_Fβ(N_F), K_Hα/K_Fα : computed from geometry
//   K_v = 1      always: the dynamic model (or the load spectrum built from it) carries
//                the dynamic mesh force, so applying K_v would count dynamics twice.
//   K_A          1 for loads from the dynamics model; the quasi-static fallback spectrum
//                (load_spectrum.hpp) passes its own application factor.
//   K_Hβ, K_Fβ   ISO 6336-1 method C (2006 edition §7.5; §7.6 in the 2019 edition) as
//                functions of the load: see MeshRating::face_load() and FaceLoadSettings
//                for every input and where it comes from. `k_h_beta_override` replaces it
//                by a constant (`drivetwin damage --k-h-beta`).
//   Y_B = 1      solid gears (rim thickness factor); Y_DT = 1 (ε_αn < 2.05).
//   Ring bending: not rated (ISO 6336-3 method B form factors are for external gears).
//   Internal mesh (planet–ring): Z_B = Z_D = 1 (ISO 6336-2 §6.2: Z_D = 1 for internal
//   gears; Z_B for the planet set to 1 as the concave-convex contact is benign).
// Basic rack: ISO 53 profile A (h_aP = 1.0·m_n, h_fP = 1.25·m_n, ρ_fP = 0.38·m_n),
// no protuberance, no tooth-thickness allowance.
//
// Thread context: rate_mesh()/mesh_rating() at start-up; MeshRating's stress functions
// are pure, allocation-free and O(1): safe on the real-time thread.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "model/drivetrain/description.hpp"

namespace model::fatigue {

/// Basic rack profile, in multiples of the normal module (ISO 53).
struct BasicRack {
  double addendum = 1.0;      // [-] h_aP / m_n
  double dedendum = 1.25;     // [-] h_fP / m_n
  double root_radius = 0.38;  // [-] ρ_fP / m_n
};

/// Lead (helix) modification of the teeth: the constants B1, B2 of ISO 6336-1:2006 method C
/// (Table 8) that weight the deflection f_sh and the manufacturing misalignment f_ma in F_βx.
enum class LeadModification : std::uint8_t {
  kNone,                        // B1 = 1,   B2 = 1
  kHelixCorrection,             // B1 = 0.1, B2 = 1    (correction for the deflection at load)
  kHelixCorrectionAndCrowning,  // B1 = 0.1, B2 = 0.5
  kCrowning,                    // B1 = 0.5, B2 = 0.5
  kEndRelief,                   // B1 = 0.7, B2 = 0.7
};
const char* lead_modification_name(LeadModification m);
/// Parses "none", "helix", "helix-crowning", "crowning", "end-relief".
std::optional<LeadModification> parse_lead_modification(std::string_view name);

/// The pinion (the smaller gear of a mesh) as ISO 6336-1 method C's component deflection
/// f_sh sees it (ISO 6336-1:2006 §7.5, eq. for f_sh with the constant 0.023 µm·mm/N):
///   f_sh = F_m/b · 0.023 · [|T + K'·l·s/d1²·(d1/d_sh)⁴ − 0.3| + 0.3] · (b/d1)²
/// T is the torsion term: 1 in ISO 6336-1 for a pinion that passes the torque of its one
/// mesh; this project generalises it to the number of meshes whose torque the pinion body
/// carries over its face width (a sun with P planets: P; an idler planet: 0), because the
/// torsional wind-up is proportional to that torque. K'·l·s/d1²·(d1/d_sh)⁴ is the bending
/// of the pinion shaft (K' per ISO 6336-1 Figure 13); 0 for a sun, whose equally spaced
/// planets balance their radial forces.
struct PinionShaft {
  double torsion_meshes = 1.0;    // [-] T above
  double k_prime = 0.0;           // [-] K', ISO 6336-1 Figure 13
  double bearing_span_m = 0.0;    // [m] l
  double offset_m = 0.0;          // [m] s, pinion mid-face to the middle of the span
  double shaft_diameter_m = 0.0;  // [m] d_sh, outer diameter of the shaft where it bends
  /// The bracket of the f_sh formula times (b/d1)², for a pinion of reference diameter d1 and face
  /// width b.
  double gamma(double d1_m, double b_m) const;
};

/// Inputs of ISO 6336-1 method C that the drivetrain description does not hold.
struct FaceLoadSettings {
  LeadModification lead = LeadModification::kHelixCorrection;  // wind gearboxes are lead-corrected
  double f_ma_factor = 1.0;   // [-] f_ma = factor·f_Hβ: 1 with no provision for adjustment,
                              //     0.5 with lapping / adjustable bearings (ISO 6336-1 §7.5)
  bool case_hardened = true;  // [-] running-in y_β: case-hardened/nitrided 0.15·F_βx ≤ 6 µm,
                              //     else 320/σ_Hlim·F_βx (no speed-dependent cap here)
  double pinion_offset_ratio = 0.25;  // [-] s/l of parallel-stage pinions (gear positions are
                                      //     not in the description; 0.25 = the intermediate
                                      //     pinion's place on its shaft in the dynamics model)
  // Initial equivalent misalignment F_βx, ISO 6336-1:2006 §7.5.2.3:
  //   false (default): eq. (52), F_βx = 1.33·B1·f_sh + B2·f_ma — the contact pattern's size
  //                    and position are not proven (nothing in a twin's data proves them);
  //   true:            eq. (53) as replaced by ISO 6336-1:2006/Cor.1:2008, F_βx = 1.33·B1·f_sh
  //                    − f_Hβ5 — the compensatory form, for a gear pair whose favourable
  //                    contact pattern under load has been VERIFIED (e.g. by a loaded contact
  //                    pattern check after a helix correction); f_Hβ5 is the helix slope
  //                    tolerance of ISO accuracy grade 5.
  // Both are floored at F_βx,min = max(0.005·F_m/b, 0.5·f_Hβ) (same clause).
  bool contact_pattern_verified = false;
};

/// Settings of the rating that the description does not hold.
struct RatingSettings {
  double k_h_beta_override = 0.0;  // [-] > 0: use this constant K_Hβ instead of method C
  FaceLoadSettings face_load{};
  int accuracy_grade =
      6;  // [-] ISO 1328-1 flank tolerance class A, for K_Hα (ISO 6336-1 method B) and f_Hβ
  double c_gamma_n_mm_um =
      20.0;  // [N/(mm·µm)] mesh stiffness c_γα, ISO 6336-1 §9 typical steel value
  BasicRack rack{};
};

/// Geometry of one gear pair (ISO 21771). Index 0 = pinion (the smaller external gear),
/// 1 = wheel. z of an internal gear is negative, as in ISO 21771, and so are its diameters.
struct PairGeometry {
  double z[2] = {0, 0};      // [-] tooth numbers (signed)
  double x[2] = {0, 0};      // [-] profile shift coefficients
  double m_n_m = 0.0;        // [m] normal module
  double alpha_n_rad = 0.0;  // [rad] normal pressure angle
  double beta_rad = 0.0;     // [rad] helix angle at the reference circle
  double b_m = 0.0;          // [m] common face width
  // Derived:
  double alpha_t_rad = 0.0;   // [rad] transverse pressure angle
  double alpha_wt_rad = 0.0;  // [rad] working transverse pressure angle
  double beta_b_rad = 0.0;    // [rad] base helix angle
  double d_m[2] = {0, 0};     // [m] reference diameters (signed)
  double da_m[2] = {0, 0};    // [m] tip diameters (signed)
  double db_m[2] = {0, 0};    // [m] base diameters (signed)
  double a_w_m = 0.0;         // [m] working centre distance (signed)
  double eps_alpha = 0.0;     // [-] transverse contact ratio ε_α
  double eps_beta = 0.0;      // [-] overlap ratio ε_β
  double u = 0.0;             // [-] gear ratio z2/z1 (negative for an internal pair)
  bool internal = false;
};

/// Builds the pair geometry from tooth data (ISO 21771 §4–5).
PairGeometry pair_geometry(double z1, double z2, double x1, double x2, double m_n_m,
                           double alpha_n_rad, double beta_rad, double b_m, const BasicRack& rack);

/// ISO 6336-3:2006 method B form and stress-correction factors of one external gear
/// (load at the outer point of single pair tooth contact).
struct BendingFormFactors {
  double y_f = 0.0;            // [-] Y_F tooth form factor
  double y_s = 0.0;            // [-] Y_S stress correction factor
  double s_fn_m = 0.0;         // [m] s_Fn root chord at the 30° tangent
  double h_fe_m = 0.0;         // [m] h_Fe bending moment arm
  double rho_f_m = 0.0;        // [m] ρ_F root fillet radius
  double alpha_fen_rad = 0.0;  // [rad] α_Fen load direction angle
};
/// @param gear 0 = pinion, 1 = wheel of `pair`; nullopt for an internal gear.
std::optional<BendingFormFactors> bending_form_factors(const PairGeometry& pair, int gear,
                                                       const BasicRack& rack);

/// ISO 6336-1 method C face load factor at one load, with its intermediate values.
struct FaceLoad {
  double line_load_n_mm = 0.0;  // [N/mm] F_m/b, F_m = F_t·K_A·K_v
  double f_sh_um = 0.0;         // [µm] component deflection
  double f_beta_x_um = 0.0;     // [µm] initial equivalent misalignment F_βx
  double y_beta_um = 0.0;       // [µm] running-in allowance y_β
  double f_beta_y_um = 0.0;     // [µm] effective equivalent misalignment F_βy
  double k_h_beta = 1.0;        // [-]
  double k_f_beta = 1.0;        // [-] K_Hβ^N_F
};

/// The four stresses of one mesh at one F_t [MPa]: what contact_stress_mpa() and
/// bending_stress_mpa() return for gears 0 and 1, with the load factors computed once.
struct MeshStresses {
  double contact_mpa[2] = {0.0, 0.0};
  double bending_mpa[2] = {0.0, 0.0};
};

/// Every factor of one mesh, and the stresses as functions of F_t.
struct MeshRating {
  PairGeometry geometry;
  double z_h = 0.0, z_e_sqrt_mpa = 0.0, z_eps = 0.0, z_beta = 0.0;  // ISO 6336-2
  double z_b = 1.0, z_d = 1.0;                                      // pinion / wheel
  double k_a = 1.0, k_v = 1.0;                                      // ISO 6336-1
  double y_beta = 1.0;                                              // ISO 6336-3
  BendingFormFactors bending[2]{};  // per gear; y_f == 0 when not rated (internal gear)
  bool bending_rated[2] = {false, false};
  // K_Hα inputs (ISO 6336-1 method B): c_γα·(f_pb − y_α) [N/mm] and the limits.
  double k_alpha_term_n_mm = 0.0;
  double k_h_alpha_max = 1.0, k_f_alpha_max = 1.0;
  double eps_gamma = 0.0;
  // K_Hβ inputs (ISO 6336-1 method C), fixed at start-up:
  double k_h_beta_fixed = 0.0;      // [-] > 0: the override, constant
  double f_sh_per_line_load = 0.0;  // [µm/(N/mm)] f_sh/(F_m/b) = 0.023·γ
  double f_h_beta_um = 0.0;     // [µm] helix slope tolerance f_Hβ (ISO 1328-1, accuracy grade)
  double f_h_beta5_um = 0.0;    // [µm] f_Hβ5: the same tolerance at accuracy grade 5
  double f_ma_um = 0.0;         // [µm] mesh misalignment from manufacturing
  double b1 = 1.0, b2 = 1.0;    // [-] lead modification constants
  double c_gamma_beta = 0.0;    // [N/(mm·µm)] c_γβ = 0.85·c_γα
  double y_beta_factor = 0.15;  // [-] y_β = factor·F_βx
  double y_beta_max_um = 6.0;   // [µm] cap of y_β (case-hardened), infinity otherwise
  double n_f = 1.0;             // [-] K_Fβ = K_Hβ^N_F (ISO 6336-1 eq. 73–74)

  bool contact_pattern_verified = false;  // F_βx by eq. (53) instead of (52), FaceLoadSettings

  /// ISO 6336-1 method C face load factors at tangential force F_t [N] (override: constant).
  FaceLoad face_load(double ft_n) const;
  /// K_Hα = K_Fα at a tangential load per face width F_t/b (ISO 6336-1:2006 eq. 75–78).
  double k_alpha(double ft_n) const;
  /// Nominal contact stress σ_H0 [MPa] (ISO 6336-2:2006 eq. 2), F_t in [N].
  double contact_stress_nominal_mpa(double ft_n) const;
  /// Contact stress σ_H [MPa] of gear 0 (pinion, Z_B) or 1 (wheel, Z_D) (ISO 6336-2 eq. 3–4).
  double contact_stress_mpa(double ft_n, int gear) const;
  /// Tooth-root stress σ_F [MPa] of gear 0/1 (ISO 6336-3:2006 eq. 3–4); 0 when not rated.
  double bending_stress_mpa(double ft_n, int gear) const;
  /// All four at once, the same numbers to the last bit (one face-load and one K_α
  /// evaluation instead of one per stress): the online accumulator's per-step path.
  MeshStresses stresses(double ft_n) const;
  /// K_α at F_t [N] with K_Hβ already known (k_alpha() evaluates it).
  double k_alpha_at(double ft_n, double k_h_beta) const;
};

/// Rates a pair of materials and geometry. `k_a` is the application factor (1 for
/// dynamic loads). E, ν from the materials; `pinion` is the pinion's body and shaft for
/// K_Hβ (the default: a pinion carrying its one mesh's torque, no shaft bending).
MeshRating mesh_rating(const PairGeometry& pair, const Material& m1, const Material& m2, double k_a,
                       const RatingSettings& settings, const PinionShaft& pinion = {});

}  // namespace model::fatigue
