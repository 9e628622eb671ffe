#pragma once
// Basic dynamic radial load rating C_r of a rolling bearing from its internal geometry,
// ISO 281:2007 §6.1.1 (radial ball bearings) and §7.1.1 (radial roller bearings):
//
//   ball   (D_w ≤ 25.4 mm):  C_r = b_m·f_c·(i·cos α)^0.7·Z^(2/3)·D_w^1.8               (§6.1.1)
//          (D_w > 25.4 mm):  C_r = 3.647·b_m·f_c·(i·cos α)^0.7·Z^(2/3)·D_w^1.4         (§6.1.1)
//   roller:                  C_r = b_m·f_c·(i·L_we·cos α)^(7/9)·Z^(3/4)·D_we^(29/27)    (§7.1.1)
//
// with D, L in mm and C_r in N; i rows, Z elements per row, α the nominal contact angle.
// f_c is interpolated linearly in γ = D·cos α/D_pw from ISO 281:2007 Table 2 (single-row
// radial-contact groove ball bearings) and Table 7 (radial roller bearings). b_m, the rating
// factor for contemporary material and manufacturing quality (ISO 281:2007 clauses 6 and 7):
// 1.3 for radial ball bearings (deep groove), 1.1 for cylindrical and tapered roller bearings.
//
// The tables here cover γ = 0.01..0.40 (ball) and 0.01..0.37 (roller). Table 7 goes on to
// 0.50, but those entries could not be checked against the closed form of ISO/TR 1281-1 here
// (test_bearing_rating.cpp checks every entry that is included), so a bearing outside the
// range is refused rather than rated from an unchecked number. Bearings with filling slots,
// self-aligning ball bearings and needle bearings (other columns of the tables) are not
// covered: give their C explicitly in the description.
//
// Thread context: start-up (ChannelSet construction); pure, no allocation.

#include "model/drivetrain/description.hpp"

namespace model::fatigue {

/// Result of rating a bearing from its geometry.
struct BearingRating {
  double c_n = 0.0;        // [N] C_r; 0 when not rated (error says why)
  double gamma = 0.0;      // [-] D·cos α/D_pw
  double f_c = 0.0;        // [-] from Table 2 / Table 7
  double b_m = 0.0;        // [-]
  const char* error = "";  // static text; empty on success
};

/// f_c of ISO 281:2007 Table 7 (radial roller bearings) at γ = D_we·cos α/D_pw; 0 outside the
/// covered range.
double roller_factor_fc(double gamma);
/// f_c of ISO 281:2007 Table 2, single-row radial-contact groove ball bearings; 0 outside.
double ball_factor_fc(double gamma);

/// ISO 281:2007 C_r of `bearing` from elements, rows, element diameter, pitch diameter, contact
/// angle and (rollers) the effective roller length `roller_effective_length_m`.
BearingRating iso281_dynamic_rating(const Bearing& bearing);

/// The rating a ChannelSet uses: `dynamic_rating_n` when the description gives one (> 0),
/// else iso281_dynamic_rating().
BearingRating effective_dynamic_rating(const Bearing& bearing);

}  // namespace model::fatigue
