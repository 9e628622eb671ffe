#pragma once
// Gear-mesh stiffness from the tooth geometry: contact ratios (ISO 21771 /
// ISO 6336-1 §3 geometry), the mean mesh stiffness of ISO 6336-1:2006 §9
// (method B: c', c_γα), the variation over one mesh cycle from the total length
// of the contact lines in the plane of action (single/double tooth contact for
// spur gears, the smoother variation of helical gears), and the relative mesh
// phasing of the planets (Parker & Lin, "Mesh phasing relationships in
// planetary and epicyclic gears", J. Mech. Des. 126 (2004)).
//
// Standard tooth proportions are assumed: addendum 1·m_n (profile shift x
// moves it), no tip relief; working pressure angle = reference (no centre
// distance modification).
//
// Thread context: start-up / model building; allocation-free but not meant for
// the real-time loop (the loop reads the PeriodicTable built here).

#include <cstddef>

#include "model/dynamics/periodic_table.hpp"

namespace model::dynamics {

/// Geometry of one gear pair. Gear 1 is the external pinion/driver side, gear 2
/// the mating gear (internal when `internal`, e.g. the ring of a planetary stage).
struct GearPair {
  int z1 = 0;                       // [-] teeth of gear 1 (external)
  int z2 = 0;                       // [-] teeth of gear 2
  bool internal = false;            // gear 2 is an internal (ring) gear
  double normal_module_m = 0.0;     // [m] m_n
  double pressure_angle_rad = 0.0;  // [rad] α_n
  double helix_angle_rad = 0.0;     // [rad] β (0: spur)
  double face_width_m = 0.0;        // [m] b
  double x1 = 0.0;                  // [-] profile shift of gear 1
  double x2 = 0.0;                  // [-] profile shift of gear 2
};

/// Derived geometry (ISO 21771). Radii are transverse.
struct MeshGeometry {
  double transverse_module_m = 0.0;                     // [m] m_t = m_n / cos β
  double transverse_pressure_angle_rad = 0.0;           // [rad] α_t = atan(tan α_n / cos β)
  double base_helix_angle_rad = 0.0;                    // [rad] β_b = atan(tan β · cos α_t)
  double pitch_radius1_m = 0.0, pitch_radius2_m = 0.0;  // [m]
  double base_radius1_m = 0.0, base_radius2_m = 0.0;    // [m]
  double tip_radius1_m = 0.0, tip_radius2_m = 0.0;      // [m] (ring: inner tip radius)
  double centre_distance_m = 0.0;                       // [m]
  double base_pitch_m = 0.0;                            // [m] transverse base pitch p_bt
  double path_of_contact_m = 0.0;                       // [m] g_α, length of the path of contact
  double pitch_point_m = 0.0;  // [m] position of the pitch point on the path, from its start
  double transverse_contact_ratio = 0.0;  // [-] ε_α = g_α / p_bt
  double overlap_ratio = 0.0;             // [-] ε_β = b sin β / (π m_n)
  double total_contact_ratio() const { return transverse_contact_ratio + overlap_ratio; }
};

MeshGeometry mesh_geometry(const GearPair& pair);

/// ISO 6336-1:2006 §9.3 (method B): single pair stiffness
/// c' = c'_th·C_M·C_R·C_B·cos β [N/(mm·µm)], with 1/c'_th = q' from the virtual
/// tooth numbers (z_n2 = ∞ for an internal gear), C_M = 0.8, C_R = 1 (solid
/// blanks), C_B for the standard basic rack (h_fP = 1.25 m_n).
double iso_single_pair_stiffness(const GearPair& pair);  // [N/(mm·µm)]

/// ISO 6336-1:2006 §9.4: mean mesh stiffness c_γα = c'·(0.75 ε_α + 0.25) [N/(mm·µm)].
double iso_mesh_stiffness(const GearPair& pair);  // [N/(mm·µm)]

/// Total length of the contact lines in the plane of action [m] at mesh phase
/// `cycles` (cycles = 0: a reference tooth pair crosses the pitch point at
/// mid face width). Spur: b × (number of pairs in contact).
///
/// `relief` ∈ [0, 1]: tip relief (a profile modification at both ends of the path of
/// contact), as the fraction of the relief that evens the stiffness out at the load it is
/// designed for. A relieved pair takes up its load along a ramp of length
/// L = relief·(g_α − p_bt) at each end of the path instead of all at once, and each piece of
/// contact line is weighted by that ramp: at relief = 1 the ramps of successive spur pairs
/// complement each other and the sum is constant ("long relief" at its design load; Smith,
/// Gear Noise and Vibration, 2003, ch. 6). 0: no modification (unrelieved involutes).
double contact_line_length_m(const MeshGeometry& g, double face_width_m, double cycles,
                             double relief = 0.0);

/// The stiffness of one mesh along its normal line of action.
struct MeshStiffness {
  double mean_n_m = 0.0;  // [N/m] mean, along the normal to the tooth flank
  PeriodicTable shape;    // [-] k(τ)/mean over one mesh cycle, mean 1
};

/// Mean from ISO 6336-1 (c_γα·b is the transverse stiffness; along the normal
/// line of action k_n = c_γα·b / cos²β_b), variation proportional to the
/// contact-line length (Cai's and Umezawa's approximation of the load-sharing
/// between pairs) with tip relief `relief` (contact_line_length_m), times `scale`.
/// The mean stays ISO 6336-1's (its c_γα is for gears with the usual modifications).
MeshStiffness mesh_stiffness(const GearPair& pair, double scale = 1.0, double relief = 0.0);

/// ISO 1328-1:1995 §6 profile form deviation tolerance f_fα of one gear [µm]: the
/// grade-5 value 2.5·√m_n + 0.17·√d + 0.5 (m_n, d in mm) times √2 per grade above 5
/// (the same step as the project's f_pT and f_Hβ, model/fatigue/gear_rating.cpp).
double iso1328_profile_form_tolerance_um(double normal_module_m, double reference_diameter_m,
                                         int grade);

/// Amplitude [m] of harmonic h ≥ 1 of a gear pair's static (unloaded, geometric)
/// transmission error that a pair of ISO 1328 flank tolerance class `grade` is expected
/// to have — the prior of the calibration, not a measurement:
///   a_h = ¼·f_pair · (1/h) · min(1, 1/(π·h·ε_β))
/// f_pair = √(f_fα,1² + f_fα,2²) (the two gears' form deviations are independent); ½ of
/// it is the amplitude of a mesh-periodic deviation of that peak-to-valley size and the
/// other ½ the share of the tolerance a manufactured flank typically uses; 1/h the decay
/// of a form deviation's Fourier series; min(1, 1/(π h ε_β)) the envelope of the
/// averaging along a helical contact line, |sin(π h ε_β)/(π h ε_β)| (Welbourn 1979),
/// without its zeros (real deviations vary across the face width).
double transmission_error_prior_m(const GearPair& pair, int grade, int harmonic);

/// e(cycles) = Σ_{h=1..count} a_h·cos(2π·h·cycles) [m], the table of a mesh element's
/// static transmission error (a MeshExcitation of VaryingStiffness).
/// phases_rad: φ_h of each harmonic (nullptr: all 0).
PeriodicTable transmission_error_table(const double* amplitudes_m, std::size_t count,
                                       const double* phases_rad = nullptr);

/// Relative mesh phases [cycles, in [0, 1)] of planet n at carrier angle ψ_n
/// (Parker & Lin 2004, eq. (2)–(3)): sun–planet γ_sn = z_s·ψ_n/2π, ring–planet
/// γ_rn = −z_r·ψ_n/2π (mod 1), for planets counted in the direction of carrier rotation.
double sun_planet_phase(int z_sun, double psi_rad);
double ring_planet_phase(int z_ring, double psi_rad);

/// Phase of a planet's ring mesh relative to its sun mesh [cycles, in [0, 1)],
/// measured as pitch-point crossings: the two pitch points are half a planet
/// revolution apart (z_p/2 pitches), the loaded flanks are opposite flanks of
/// the planet tooth (one circular tooth thickness, s = p/2 for x = 0, apart):
/// γ_rs = (z_p − 1)/2 mod 1 — 0 for an odd z_p, ½ for an even z_p.
double ring_sun_phase(int z_planet);

}  // namespace model::dynamics
