#pragma once
// A rolling bearing's varying compliance: the radial force it carries at a fixed deflection
// changes as its rolling elements pass through the load zone, once per element passing the
// outer race (BPFO), so its stiffness fluctuates at BPFO and its harmonics even when it is
// perfect (Sunnersjö, J. Sound Vib. 58 (1978); Harris & Kotzalas, Rolling Bearing Analysis,
// ch. 7–8).
//
// Element j at cage angle ψ_j = ψ + 2πj/Nb from the load direction, the inner ring displaced
// by δ along it, zero operating clearance (the load zone of ±90°, ISO 281's reference ε = 0.5):
// its contact deflection is δ·cos ψ_j where positive, its load Q_j = K_n·(δ cos ψ_j)^n with
// n = 10/9 for a roller's line contact (Palmgren: δ = 3.84e-5·Q^0.9/L_we^0.8 per raceway,
// δ in mm, Q in N, L_we in mm) and n = 3/2 for a ball's point contact (Hertz), and the bearing's
// force along the load is F(ψ) = Σ_j Q_j·cos ψ_j = K_n·δ^n·Σ_{cos ψ_j > 0} cos^(n+1) ψ_j.
// K_n (the roller length, the ring curvatures) and δ^n cancel in F(ψ)/F̄: with zero clearance
// the shape depends on the number of elements and the contact law only, not on the load (the
// law is homogeneous in δ). A radial clearance narrows the load zone as the load falls and
// raises the fluctuation (clearance/2 = 0.5·δ: ~1–2 % at 14–22 elements; 0.9·δ: up to 7 %);
// the operating clearance of a gearbox bearing is not known, so the calibration scales the
// derived fluctuation with a wide prior (calibration_space.cpp).
//
// A paired (two-row) set: both rows at the same cage angle (the upper bound of their sum).
// The perpendicular force the asymmetric roller set carries (Σ Q_j sin ψ_j, zero mean) is not
// modelled: the bearing's k(t) is isotropic in x and y (full_model.hpp).
//
// Thread context: model building (off the real-time thread); allocation-free, O(Nb·256).

#include "model/drivetrain/description.hpp"
#include "model/dynamics/periodic_table.hpp"

namespace model::dynamics {

/// Load–deflection exponent n of one rolling element, Q ∝ δ^n: 10/9 (roller, line contact),
/// 3/2 (ball, point contact).
double rolling_contact_exponent(BearingType type) noexcept;

/// F(ψ)/F̄ at a fixed radial deflection over one element pitch (table position c ∈ [0, 1):
/// element 0 at ψ = 2πc/Nb from the load direction), zero operating clearance.
/// `elements` ≥ 1 (per row).
PeriodicTable bearing_load_zone_force(int elements, BearingType type) noexcept;

/// The stiffness shape of a bearing in the dynamics models: 1 + scale·(F(c)/F̄ − 1) +
/// cosine_amplitude·cos 2πc — the derived varying compliance, scaled (1: as derived; 0: none),
/// plus an explicit cosine (DynamicsParameters::bearing_stiffness_fluctuation; 0.1 by
/// default, the prior the standard space fits).
PeriodicTable bearing_stiffness_shape(int elements, BearingType type, double scale,
                                      double cosine_amplitude) noexcept;

}  // namespace model::dynamics
