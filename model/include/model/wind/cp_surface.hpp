#pragma once
// Power coefficient surface Cp(λ, β) of a rotor (the aerodynamic half of the
// paper's wind load model, VBDM-DT section 2: input torque from wind speed).
//
// Form (Heier, "Grid Integration of Wind Energy Conversion Systems", 1998;
// Slootweg et al., IEEE Trans. Power Syst. 18(1), 2003, eq. 3–4), with a
// tip-speed-ratio scale s that places λ_opt without reshaping the curve:
//
//   λ' = s·λ
//   1/λ_i = 1/(λ' + a·β) − b/(β³ + 1)                 β in degrees (as in Heier)
//   Cp    = c1·(c2/λ_i − c3·β − c4)·exp(−c5/λ_i) + c6·λ'
//
// with c = CpSurface::c, a = CpSurface::lambda_i_beta, b = CpSurface::lambda_i_cubic,
// s = CpSurface::lambda_scale. The textbook coefficients c = {0.5176, 116, 0.4, 5,
// 21, 0.0068}, a = 0.08, b = 0.035 give Cp_max ≈ 0.48 at λ ≈ 8.1, β = 0.
// Negative values (a rotor driven by the generator) are clamped to 0: the twin
// estimates the load a turning rotor puts on the drivetrain, never motoring.
//
// Tabulated alternative (CpSurface::table_cp, when table_lambda_max > table_lambda_min):
// Cp(λ', 0) is the monotone piecewise-cubic Hermite interpolant (Fritsch & Carlson,
// SIAM J. Numer. Anal. 17(2), 1980) of kCpTableKnots values at equally spaced λ',
// held at the end values outside the knots. It is C¹ and never leaves the range of
// the neighbouring knot values, so knots within [0, 16/27] keep Cp below the Betz
// limit everywhere. Pitch enters as Heier's relative factor:
//   Cp(λ', β) = Cp_table(λ') · Cp_Heier(λ', β) / Cp_Heier(λ', 0)   (0 when the denominator is).
//
// Thread context: pure functions of their arguments, no allocation, no
// exceptions, no blocking; safe on the real-time thread.

#include "model/drivetrain/description.hpp"

namespace model::wind {

/// The Betz limit 16/27: the most a free-stream actuator disc can extract.
inline constexpr double kBetzLimit = 16.0 / 27.0;

/// Whether the surface uses its Cp(λ) table rather than Heier's c1..c6.
bool has_cp_table(const CpSurface& surface);

/// Cp(λ, β) of the surface above, clamped to [0, ∞).
/// @param surface          coefficients (description's Turbine::cp)
/// @param tip_speed_ratio  λ = ω·R / v [-]; λ ≤ 0 gives 0
/// @param pitch_rad        blade pitch β [rad] (0 = fine pitch)
/// @return power coefficient [-]
double power_coefficient(const CpSurface& surface, double tip_speed_ratio, double pitch_rad);

/// The maximum of the surface along β = 0 and where it lies.
struct CpPeak {
  double cp_max = 0.0;      // [-]
  double lambda_opt = 0.0;  // [-] tip-speed ratio of cp_max
};

/// Finds the maximum of Cp(λ, 0) over λ ∈ [1, 20] by a coarse scan (step 0.05)
/// refined by golden-section search to |Δλ| < 1e-6. Used at construction of
/// WindLoad; also the independent check that a surface reproduces a published
/// Cp_max / λ_opt.
CpPeak find_cp_peak(const CpSurface& surface);

}  // namespace model::wind
