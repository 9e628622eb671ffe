#pragma once
// What ISO 281:2007 puts on a bearing's life besides C: the modified rating life
//
//   L_nm = a1 · a_ISO · L10,   L10 = (C/P)^p million revolutions          (ISO 281:2007 §9.1)
//
// a1 = 1 (90 % reliability, the L10 the twin reports). a_ISO (§9.3) follows from the viscosity
// ratio κ and the contamination term e_C·C_u/P:
//   radial roller bearings, 0.1 ≤ κ < 0.4:  a_ISO = 0.1·[1 − (1.5859
//   − 1.3993/κ^0.054381)·x^0.4]^−9.185
//                           0.4 ≤ κ < 1:    0.1·[1 − (1.5859 − 1.2348/κ^0.19087)·x^0.4]^−9.185
//                           1 ≤ κ ≤ 4:      0.1·[1 − (1.5859 − 1.2348/κ^0.071739)·x^0.4]^−9.185
//   radial ball bearings:   0.1·[1 − (2.5671 − k1/κ^k2)^0.83·x^(1/3)]^−9.3 with k1 = 2.2649,
//                           1.9987, 1.9987 and k2 = 0.054381, 0.19087, 0.071739 in the same ranges
// with x = e_C·C_u/P, a_ISO ≤ 50, κ > 4 taken as 4 and κ < 0.1 as 0.1 (the standard's curves end
// there; below 0.1 it gives no value, and this code stays at the 0.1 curve, stated in the
// reports). The three κ branches join within 3e-4 at 0.4 and exactly at 1.
//
// κ = ν/ν1: ν the oil's kinematic viscosity at the operating temperature, from its ν40 and ν100
// by the Walther/ASTM D341 relation log log(ν + 0.7) = A − B·log T; ν1 the rated viscosity
// of ISO 281:2007 §9.3.3 (fig. 5): ν1 = 45000·n^−0.83·D_pw^−0.5 mm²/s for n < 1000 rpm,
// 4500·n^−0.5·D_pw^−0.5 for n ≥ 1000 rpm (n the ring's relative speed in rpm, D_pw in mm).
//
// C_u, the fatigue load limit, when a description gives none: ISO 281:2007's approximation
// from C0 — roller bearings C0/8.2 for D_pw ≤ 100 mm, C0/8.2·(100/D_pw)^0.3 above; ball
// bearings C0/27 and C0/27·(100/D_pw)^0.5. C0 from the geometry by ISO 76:2006 for radial
// roller bearings, C0 = 44·(1 − D_we·cos α/D_pw)·i·Z·L_we·D_we·cos α (N, mm); ball bearings
// need it given.
//
// e_C (ISO 281:2007 Table 13) is an input: for D_pw ≥ 100 mm "normal cleanliness, oil filtered
// through a fine filter" is 0.8–0.6, "slight contamination" 0.6–0.4. The standard's detailed
// method (Annex A: e_C from κ, D_pw, the filter rating and the ISO 4406 code) is not here.
//
// Thread context: pure functions; life_modification_factor() allocates nothing (real-time).

#include "model/drivetrain/description.hpp"

namespace model::fatigue {

/// The lubricant and cleanliness a_ISO is computed with (documented defaults, see fatigue.md).
struct Lubrication {
  bool enabled = true;                 // false: a_ISO = 1 (the basic rating life L10)
  double viscosity_40c_mm2_s = 320.0;  // [mm²/s] ν40: ISO VG 320, the usual wind-gearbox grade
  double viscosity_100c_mm2_s = 35.0;  // [mm²/s] ν100: a PAO (synthetic) VG 320, VI ≈ 150
  double temperature_c = 70.0;         // [°C] bearing operating temperature (oil sump + rise)
  double contamination_factor = 0.6;   // [-] e_C: the lower end of "normal cleanliness"
};

/// Kinematic viscosity at a temperature from the values at 40 and 100 °C (ASTM D341) [mm²/s].
double kinematic_viscosity_mm2_s(double nu40_mm2_s, double nu100_mm2_s, double temperature_c);

/// ISO 281:2007 rated viscosity ν1 [mm²/s] at a relative ring speed and pitch diameter.
/// @param speed_rpm           n [rpm], > 0
/// @param pitch_diameter_mm   D_pw [mm]
double rated_viscosity_mm2_s(double speed_rpm, double pitch_diameter_mm);

/// ISO 281:2007 a_ISO of a radial bearing (≤ 50; κ clamped to [0.1, 4]).
/// @param type             ball or roller
/// @param kappa            ν/ν1
/// @param ec_cu_over_p     e_C·C_u/P (≥ 0)
double life_modification_factor(BearingType type, double kappa, double ec_cu_over_p);

/// ISO 76:2006 C0 of a radial roller bearing from its geometry [N]; 0 for a ball bearing or an
/// incomplete geometry (no roller length).
double iso76_static_rating_n(const Bearing& bearing);

/// C0 in use: the description's `static_rating_n` when > 0, else iso76_static_rating_n().
double effective_static_rating_n(const Bearing& bearing);

/// C_u in use: the description's `fatigue_load_limit_n` when > 0, else ISO 281:2007's
/// approximation from C0 (above); 0 when neither is available.
double effective_fatigue_load_limit_n(const Bearing& bearing);

}  // namespace model::fatigue
