#pragma once
// Fitting the Cp(λ, β) surface of a turbine to SCADA (`drivetwin fit-cp`).
//
// Method: minimise the mean absolute relative torque error (the MAPE the model
// is judged by) by iteratively reweighted Levenberg–Marquardt (Eigen's
// unsupported module, forward-difference Jacobian) of
//   r_i = (T_model,i(p) − T_ref,i) / T_ref,i
// over the rows in operation (app/wind/torque_estimate.hpp) of the fitting
// window. T_model is WindLoad::with_rotor_speed with the measured rotor speed,
// pitch and inflow (density, yaw error) of row i, limited to rated torque, and
// converted to the reference's side: against P_i/ω_i (measured power) it is
// (η·T·ω_i − P_0)/ω_i, against a measured torque it is T.
// Parameters p: the Cp amplitude c1 and the λ scale s of the textbook shape
// (Heier; Slootweg et al. 2003), or, with FitOptions::cp_table, the
// kCpTableKnots knot values of a tabulated Cp(λ) (model/wind/cp_surface.hpp),
// each Cp_k = (16/27)·σ(q_k) with q_k free and σ the logistic function, so that
// every knot and hence the whole monotone interpolant stays within the Betz
// limit; the knots span λ from 0.9·ω_rated·R/v_rated to 1.1·ω_min·R/v_cut_in,
// the tip-speed ratios of the rows in operation below rated wind with a margin
// for 10-minute averaging (from the description alone, before any fit), and a
// weak pull of each knot towards its textbook value keeps knots without data
// where the textbook puts them (cp_fit.cpp, kKnotPriorWeight).
// Cp(λ, 0) of a rotor has one maximum: table steps that rise above the tracked tip-speed
// ratio (or fall below it) are penalised (cp_fit.cpp, kShapeWeight), which keeps the
// anemometer's scatter at the speed floor from bending the table upwards at high λ
// (regression dilution: E[P | v_nacelle] is flatter than P(v)). IRLS rounds need not lower
// the L1 objective monotonically: the best point over the rounds is kept.
// With FitOptions also the tracked tip-speed ratio λ_c, the tracking band margin m and the
// within-row turbulence intensity I (model/wind/wind_load.hpp), the no-load loss
// P_0, the nacelle transfer function's offset b (gain a stays 1: with a and b
// free, a trades against c1 and s), and the yaw loss exponent x
// (model/wind/corrections.hpp); the corrections not freed are set to none. The
// fit always starts from the textbook surface, P_0 = 0, b = 0 and x = 2, so that
// re-running it gives the same result whatever the description currently holds.
//
// Thread context: command code (allocates, holds the fitting rows in memory).

#include <cstddef>
#include <string>
#include <vector>

#include "hal/scada_csv.hpp"
#include "model/drivetrain/description.hpp"
#include "model/wind/wind_load.hpp"
#include "wind/torque_estimate.hpp"

namespace app::wind {

/// One row used for fitting.
struct FitRow {
  double wind_speed_mps;     // [m/s] measured (nacelle)
  double rotor_speed_rad_s;  // [rad/s] measured
  double pitch_rad;          // [rad]
  bool has_pitch;
  double reference_torque_nm;  // [N·m] P/ω when electrical_reference, else measured torque
  bool electrical_reference = false;
  model::wind::Inflow inflow{};  // measured density and yaw error (defaults: none)
};

/// The fitting row of a SCADA row estimated in operation: measured wind, speed,
/// reference, the density the estimate used (when measured) and the yaw error
/// (kept whatever the description's exponent, since the fit may free it).
FitRow fit_row_of(const hal::ScadaRow& row, const RowEstimate& estimate);

/// Which parameters besides c1 and s the fit frees.
struct FitOptions {
  bool cp_table = false;        // fit the Cp(λ) table's knots instead of c1 and s
  bool no_load_loss = false;    // P_0
  bool nacelle_offset = false;  // b of v_free = a·v_nacelle + b
  bool nacelle_gain = false;    // a
  bool yaw_exponent = false;    // x of cos^x(γ)
  bool tracking_tsr = false;    // λ_c, the tip-speed ratio the controller tracks
  bool tracking_band = false;   // m, where the measured speed gives the wind ωR/λ_c
  bool turbulence = false;      // I, the spread of the wind within a row
};

struct CpFitResult {
  model::CpSurface surface;                     // fitted
  model::TurbineCorrections corrections;        // fitted where FitOptions frees them, else as given
  std::size_t rows = 0;                         // rows fitted
  double mean_abs_relative_error_before = 0.0;  // [-] with the textbook start
  double mean_abs_relative_error_after = 0.0;   // [-]
  int lm_status = 0;                            // Eigen::LevenbergMarquardtSpace::Status
  int iterations = 0;
};

/// The textbook surface (Heier; Slootweg et al. 2003): the fit's starting point.
model::CpSurface textbook_cp_surface();

/// The textbook surface with a Cp(λ) table spanning the turbine's operating tip-speed
/// ratios (see above), knots on the textbook curve: the table fit's starting point.
model::CpSurface textbook_cp_table(const model::Turbine& turbine);

/// Fits the surface of `turbine` (its other fields fixed) to `rows`; with
/// `options`, also the corrections it frees (the others are set to none).
CpFitResult fit_cp_surface(const model::Turbine& turbine, const std::vector<FitRow>& rows,
                           const FitOptions& options = {});

/// `[turbine.corrections]` table text.
std::string corrections_table_toml(const model::TurbineCorrections& corrections);

/// Replaces the table `[header]` of a TOML text with `table` (up to the next table
/// header or the end), or appends it when the text has none.
std::string replace_or_append_table(const std::string& text, const std::string& header,
                                    const std::string& table);

/// `[turbine.cp]` table text of a surface (for pasting into / updating a file).
std::string cp_table_toml(const model::CpSurface& surface);

/// Replaces the `[turbine.cp]` table of a TOML description text with `table`
/// (up to the next table header or the end). Throws if the file has none.
std::string replace_cp_table(const std::string& text, const std::string& table,
                             const std::string& source);

}  // namespace app::wind
