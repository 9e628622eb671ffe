#pragma once
// Fitting the Cp(λ, β) surface of a turbine to SCADA (`drivetwin fit-cp`).
//
// Method: nonlinear least squares (Levenberg–Marquardt, Eigen's unsupported
// module, forward-difference Jacobian) of the relative torque error
//   r_i = (T_model(v_i, ω_i, β_i; p) − T_ref,i) / T_ref,i
// over the rows in operation (app/wind/torque_estimate.hpp) of the fitting
// window, where T_model is WindLoad::with_rotor_speed with the measured rotor
// speed ω_i and pitch β_i (limited to rated torque), and T_ref,i = P_i/(η·ω_i).
// Parameters p = (c1..c6, lambda_i_beta); lambda_i_cubic and lambda_scale stay
// as given (the scale is redundant with c2/c5 when all of c are free). The fit
// always starts from the textbook coefficients (Slootweg et al. 2003), so that
// re-running it gives the same result whatever the description's current Cp.
//
// Thread context: command code (allocates, holds the fitting rows in memory).

#include <cstddef>
#include <string>
#include <vector>

#include "model/drivetrain/description.hpp"

namespace app::wind {

/// One row used for fitting.
struct FitRow {
  double wind_speed_mps;
  double rotor_speed_rad_s;
  double pitch_rad;
  bool has_pitch;
  double reference_torque_nm;
};

struct CpFitResult {
  model::CpSurface surface;     // fitted
  std::size_t rows = 0;         // rows fitted
  double mean_abs_relative_error_before = 0.0;  // [-] with the textbook start
  double mean_abs_relative_error_after = 0.0;   // [-]
  int lm_status = 0;            // Eigen::LevenbergMarquardtSpace::Status
  int iterations = 0;
};

/// The textbook surface (Heier; Slootweg et al. 2003): the fit's starting point.
model::CpSurface textbook_cp_surface();

/// Fits the surface of `turbine` (its other fields fixed) to `rows`.
CpFitResult fit_cp_surface(const model::Turbine& turbine, const std::vector<FitRow>& rows);

/// `[turbine.cp]` table text of a surface (for pasting into / updating a file).
std::string cp_table_toml(const model::CpSurface& surface);

/// Replaces the `[turbine.cp]` table of a TOML description text with `table`
/// (up to the next table header or the end). Throws if the file has none.
std::string replace_cp_table(const std::string& text, const std::string& table,
                             const std::string& source);

}  // namespace app::wind
