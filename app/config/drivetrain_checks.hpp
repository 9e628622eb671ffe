#pragma once
// Physical validation of a drivetrain description (the whole description, after a file
// is merged onto its base): what the key-by-key ranges of the file format cannot see.
// parse_drivetrain() and load_drivetrain() run it, so every command that loads a
// description refuses an impossible gearbox with the file, the key and the rule named.
//
// Gear stages (ISO 21771 geometry; involute gears, basic rack h_a* = 1):
//   - ranges: pressure angle 10–35° (ISO 53's 20°; 14.5–25° in use), helix angle 0–45°
//     (single helical 8–20°, double helical to 45°), profile shift −1 ≤ x ≤ 2;
//   - undercut: every external gear z ≥ 5/6 · 2(1 − x)·cos β / sin²α_t rounded (the
//     practical limit, slight undercut allowed: 14 teeth at 20°, x = 0, spur);
//   - pointed tips: normal tip thickness s_an ≥ 0.2·m_n on every external gear;
//   - contact: every mesh's total contact ratio ε_γ = ε_α + ε_β ≥ 1;
//   - planetary (fixed ring, carrier input, sun output; KHK's profile-shift convention
//     for the internal ring, inv α_w = inv α_t + 2 tan α_n (x_r − x_p)/(z_r − z_p)):
//       * planets 1–12, ring teeth > planet teeth;
//       * coaxiality: the sun–planet and ring–planet operating centre distances are
//         equal within 0.01·m_n (with x = 0: z_ring − z_sun = 2·z_planet);
//       * neighbouring planets clear: 2·a_w·sin(π/N) − d_a,planet ≥ 0.5·m_n;
//       * assembly with equally spaced planets: (z_ring + z_sun) / N an integer;
//   - parallel stages: two gears.
// Turbine:
//   - turbine.cp_max and the Cp surface's own maximum (model/wind find_cp_peak) at or
//     below the Betz limit 16/27;
//   - a consistent rated point: drivetrain_efficiency · rated_torque_nm · rated speed
//     within 20 % of rated_power_w, and the Cp it takes to deliver rated torque at rated
//     speed from the rated wind at or below the Betz limit.
// Materials (ISO 6336-5's ranges): Poisson's ratio < 0.5, σ_Hlim 200–2000 MPa,
// σ_Flim 100–1000 MPa, Young's modulus 50–400 GPa; S-N exponents ≥ 1.
//
// Thread context: start-up only (allocates).

#include <string>
#include <vector>

#include "model/drivetrain/description.hpp"

namespace app::config {

/// One violated rule: `list` and `id` locate the entry (list "" for top-level tables),
/// `key` is the full dotted key (e.g. "stages[0].planets"), `message` what was found
/// and what was expected.
struct DrivetrainIssue {
  std::string list;   // "gears", "stages", "materials", "turbine", ...
  std::string id;     // the entry's id ("" for a table)
  std::string field;  // the key inside the entry ("teeth", "planets", ...)
  std::string key;
  std::string message;
};

/// Every violated rule above, in the order the file lists the entries.
std::vector<DrivetrainIssue> check_drivetrain(const model::Drivetrain& drivetrain);

/// ISO 1328-1:2013 accuracy classes (the K_Hα, K_Hβ tolerances use its √2 steps).
inline constexpr int kMinAccuracyGrade = 1;
inline constexpr int kMaxAccuracyGrade = 11;

}  // namespace app::config
