// `drivetwin fit-cp <scada.csv>`: fits the Cp(λ, β) surface and the SCADA
// corrections (no-load loss, nacelle transfer function, tracked tip-speed ratio and band,
// within-row turbulence, yaw loss exponent) of a drivetrain description to SCADA rows in
// operation (method: app/wind/cp_fit.hpp), prints the fitted [turbine.cp] and
// [turbine.corrections] tables, optionally the MAPE on a held-out window (times or calendar
// months), its breakdown per month, region and wind bin, and a leave-one-season-out test
// (app/wind/heldout.hpp); with --update FILE writes both tables into FILE.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "cli/command.hpp"
#include "cli/wind_options.hpp"
#include "config/drivetrain_file.hpp"
#include "fatigue/progress.hpp"
#include "hal/scada_csv.hpp"
#include "model/wind/cp_surface.hpp"
#include "wind/cp_fit.hpp"
#include "wind/heldout.hpp"
#include "wind/torque_estimate.hpp"

namespace {

// A fitted maximum this close to the Betz limit is reported as suspect.
constexpr double kBetzSuspectFraction = 0.97;

struct FitArgs {
  std::string file;
  std::string drivetrain;
  std::string columns = "bundle";
  std::string from;
  std::string to;
  std::string test_from;
  std::string test_to;
  std::string fit_months;
  std::string test_months;
  bool breakdown = false;
  std::string leave_one_out;
  std::string free = "table,loss,offset,gain,tracking-tsr,tracking-band,turbulence";
  bool constant_density = false;
  bool no_progress = false;
  std::string update;
};

app::wind::FitOptions parse_free(const std::string& text) {
  app::wind::FitOptions o;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (item == "table") {
      o.cp_table = true;
    } else if (item == "loss") {
      o.no_load_loss = true;
    } else if (item == "offset") {
      o.nacelle_offset = true;
    } else if (item == "gain") {
      o.nacelle_gain = true;
    } else if (item == "yaw") {
      o.yaw_exponent = true;
    } else if (item == "tracking-tsr") {
      o.tracking_tsr = true;
    } else if (item == "tracking-band") {
      o.tracking_band = true;
    } else if (item == "turbulence") {
      o.turbulence = true;
    } else if (item != "none" && !item.empty()) {
      throw app::cli::CommandError(
          "--free: unknown parameter '" + item +
          "' (expected a list of table, loss, offset, gain, yaw, tracking-tsr, tracking-band, "
          "turbulence, or none)");
    }
  }
  return o;
}

app::wind::EstimatorOptions fit_estimator_options(const FitArgs& args) {
  app::wind::EstimatorOptions options;
  options.measured_temperature = !args.constant_density;
  return options;
}

app::wind::TorqueSummary evaluate(const FitArgs& args, const hal::ScadaColumns& columns,
                                  const model::Drivetrain& d, const app::wind::TimeWindow& window,
                                  std::vector<app::wind::FitRow>* rows,
                                  app::wind::ErrorBreakdown* breakdown = nullptr) {
  try {
    return app::wind::evaluate_scada(args.file, columns, d, fit_estimator_options(args), window,
                                     breakdown, rows);
  } catch (const std::runtime_error& e) {
    throw app::cli::CommandError(e.what());
  }
}

void print_mape(const char* label, const app::wind::MapeAccumulator& m) {
  std::printf(
      "%s MAPE: region 2 %.2f %% (%zu rows), 2.5 %.2f %% (%zu), 3 %.2f %% (%zu), all %.2f %% "
      "(%zu)\n",
      label, m.mape_pct(0), m.count(0), m.mape_pct(1), m.count(1), m.mape_pct(2), m.count(2),
      m.mape_pct(), m.count());
}

app::wind::TimeWindow window_of(const std::string& from, const std::string& to,
                                const std::string& months, const char* from_name,
                                const char* to_name, const char* months_name) {
  app::wind::TimeWindow w;
  if (!from.empty()) w.from_s = app::wind::parse_time_option(from_name, from);
  if (!to.empty()) w.to_s = app::wind::parse_time_option(to_name, to);
  if (!months.empty()) {
    std::string error;
    const auto set = app::wind::MonthSet::parse(months, &error);
    if (!set) throw app::cli::CommandError(std::string(months_name) + ": " + error);
    w.months = set->mask();
  }
  return w;
}

void print_breakdown(const char* label, const app::wind::ErrorBreakdown& b) {
  std::printf("# %s, per month and region:\n%s# %s, per wind-speed bin (nacelle wind):\n%s", label,
              b.month_table().c_str(), label, b.wind_table().c_str());
}

void run(const FitArgs& args) {
  model::Drivetrain d = app::config::load_drivetrain(args.drivetrain);
  std::string error;
  const auto columns = hal::parse_scada_columns(args.columns, &error);
  if (!columns) throw app::cli::CommandError("--columns: " + error);
  const app::wind::FitOptions options = parse_free(args.free);
  const app::wind::TimeWindow window =
      window_of(args.from, args.to, args.fit_months, "--from", "--to", "--fit-months");

  std::vector<app::wind::FitRow> rows;
  const auto before = evaluate(args, *columns, d, window, &rows);
  // Rejected rows (app/wind/scada_rows.hpp): skipped in the fit and in every MAPE below,
  // named on stderr once, exit 2; the fit (and --update) rests on the other rows.
  if (before.rejected.rows_rejected > 0) {
    before.rejected.print(stderr, "drivetwin fit-cp: ");
    app::cli::exit_status() = 2;
  }
  const app::wind::CpFitResult fit = app::wind::fit_cp_surface(d.turbine, rows, options);
  d.turbine.cp = fit.surface;
  d.turbine.corrections = fit.corrections;
  const model::wind::CpPeak peak = model::wind::find_cp_peak(fit.surface);

  std::printf("# fit-cp %s (%s .. %s), drivetrain %s, %zu rows in operation, %zu rejected\n",
              args.file.c_str(), args.from.empty() ? "start" : args.from.c_str(),
              args.to.empty() ? "end" : args.to.c_str(), d.name.c_str(), fit.rows,
              before.rejected.rows_rejected);
  std::printf("# free: %s%s%s%s%s%s%s%s; air density: %s\n",
              options.cp_table ? "Cp(lambda) table knots" : "c1, lambda_scale",
              options.no_load_loss ? ", no_load_loss_w" : "",
              options.nacelle_offset ? ", nacelle_wind_offset_mps" : "",
              options.nacelle_gain ? ", nacelle_wind_gain" : "",
              options.yaw_exponent ? ", yaw_loss_exponent" : "",
              options.tracking_tsr ? ", tracking_tip_speed_ratio" : "",
              options.tracking_band ? ", tracking_band_margin" : "",
              options.turbulence ? ", turbulence_intensity" : "",
              args.constant_density || before.density_rows == 0
                  ? "constant (description's air_density_kg_m3)"
                  : "from the ambient temperature column at site_altitude_m (ISA pressure)");
  std::printf(
      "# Levenberg-Marquardt status %d after %d iterations; mean |relative torque error| "
      "%.4f (start) -> %.4f\n",
      fit.lm_status, fit.iterations, fit.mean_abs_relative_error_before,
      fit.mean_abs_relative_error_after);
  std::printf("# fitted surface: Cp_max %.4f at lambda_opt %.3f (beta = 0)\n", peak.cp_max,
              peak.lambda_opt);
  if (options.tracking_tsr || options.tracking_band || options.turbulence) {
    std::printf(
        "# rotor-effective wind: tracked tip-speed ratio %.3f, tracking band margin %.4f, "
        "turbulence intensity %.4f\n",
        fit.corrections.tracking_tip_speed_ratio, fit.corrections.tracking_band_margin,
        fit.corrections.turbulence_intensity);
  }
  // Plausibility: no rotor extracts more than the Betz limit; one at it is suspect too.
  if (peak.cp_max > model::wind::kBetzLimit + 1e-9) {
    char text[600];
    std::snprintf(text, sizeof text,
                  "the fitted surface's Cp_max %.4f (at lambda %.2f) is above the Betz limit "
                  "16/27 = 0.5926: no rotor extracts that much, so the fit is compensating for "
                  "something the description gets wrong — the measured power or torque "
                  "(drivetrain_efficiency %.3f, no_load_loss_w), the wind speed (a nacelle "
                  "anemometer reads low: free offset and gain), the air density or the rotor "
                  "radius. No table printed, nothing written; free fewer parameters or fix those",
                  peak.cp_max, peak.lambda_opt, d.turbine.drivetrain_efficiency);
    throw app::cli::CommandError(std::string("fit-cp: ") + text);
  }
  if (peak.cp_max >= kBetzSuspectFraction * model::wind::kBetzLimit) {
    std::printf(
        "# NOTE: the fitted Cp_max %.4f is at the Betz limit 0.5926 (>= %.0f %% of it): real "
        "rotors of this size peak near 0.45-0.50; the fit is pressing against physics, and the "
        "torques it gives rest on that\n",
        peak.cp_max, 100.0 * kBetzSuspectFraction);
    std::fprintf(stderr, "fit-cp: note: fitted Cp_max %.4f is at the Betz limit (suspect)\n",
                 peak.cp_max);
  }
  app::wind::ErrorBreakdown fit_breakdown;
  const auto summary = evaluate(args, *columns, d, window, nullptr, &fit_breakdown);
  print_mape("# fitting window", summary.mape);
  const bool held_out_window =
      !args.test_from.empty() || !args.test_to.empty() || !args.test_months.empty();
  if (held_out_window) {
    const app::wind::TimeWindow test = window_of(args.test_from, args.test_to, args.test_months,
                                                 "--test-from", "--test-to", "--test-months");
    app::wind::ErrorBreakdown test_breakdown;
    const auto held_out = evaluate(args, *columns, d, test, nullptr, &test_breakdown);
    print_mape("# held-out window", held_out.mape);
    if (args.breakdown) print_breakdown("held-out window", test_breakdown);
  } else if (args.breakdown) {
    print_breakdown("fitting window", fit_breakdown);
  }
  if (!args.leave_one_out.empty()) {
    // Folds over the --from/--to window (all its months), each fitted like the main fit.
    app::wind::TimeWindow base = window;
    base.months = app::wind::MonthSet::all().mask();
    const auto folds = args.leave_one_out == "months" ? app::wind::single_months()
                                                      : app::wind::meteorological_seasons();
    model::Drivetrain start = app::config::load_drivetrain(args.drivetrain);
    std::vector<app::wind::FoldResult> results;
    // One fold at a time (each is independent: a fit on the others, a test on it), so a
    // terminal sees the progress: ~3 s a fold for a year of Kelmarsh rows.
    app::fatigue::ProgressLine progress(
        app::fatigue::show_progress(args.no_progress, STDERR_FILENO), "leave-one-out fits", "folds",
        static_cast<double>(folds.size()));
    try {
      for (const auto& fold : folds) {
        auto one = app::wind::leave_one_out(args.file, *columns, start, fit_estimator_options(args),
                                            base, {fold}, options);
        for (auto& r : one) results.push_back(std::move(r));
        progress.update(static_cast<double>(results.size()));
      }
    } catch (const std::runtime_error& e) {
      throw app::cli::CommandError(e.what());
    }
    progress.finish();
    std::printf("# leave one %s out (fit on the others, test on it):\n%s",
                args.leave_one_out == "months" ? "month" : "season",
                app::wind::leave_one_out_table(results).c_str());
  }
  const std::string cp_table = app::wind::cp_table_toml(fit.surface);
  const std::string corrections_table = app::wind::corrections_table_toml(fit.corrections);
  std::printf("%s\n%s", cp_table.c_str(), corrections_table.c_str());

  if (!args.update.empty()) {
    std::ifstream in(args.update, std::ios::binary);
    if (!in) throw app::cli::CommandError(args.update + ": cannot read");
    std::stringstream text;
    text << in.rdbuf();
    std::string updated = app::wind::replace_cp_table(text.str(), cp_table, args.update);
    updated = app::wind::replace_or_append_table(updated, "turbine.corrections", corrections_table);
    in.close();
    // Check the result still parses before overwriting.
    (void)app::config::parse_drivetrain(updated, args.update);
    std::ofstream out(args.update, std::ios::binary | std::ios::trunc);
    out << updated;
    if (!out) throw app::cli::CommandError(args.update + ": cannot write");
    std::printf("# wrote [turbine.cp] and [turbine.corrections] into %s\n", args.update.c_str());
  }
}

void setup_fit_cp(CLI::App& sub) {
  auto args = std::make_shared<FitArgs>();
  sub.add_option("scada_csv", args->file, "SCADA CSV with wind, rotor speed, pitch and power")
      ->required();
  app::config::add_drivetrain_option(sub, args->drivetrain);
  sub.add_option("--columns", args->columns,
                 "Column mapping: bundle, kelmarsh or 'field=Column;...'");
  sub.add_option("--from", args->from, "Fit rows at or after this UTC time (YYYY-MM-DD[ HH:MM:SS])")
      ->check(app::cli::utc_time());
  sub.add_option("--to", args->to, "Fit rows before this UTC time")->check(app::cli::utc_time());
  sub.add_option("--test-from", args->test_from,
                 "Also report the MAPE of the fitted description on rows from this time")
      ->check(app::cli::utc_time());
  sub.add_option("--test-to", args->test_to, "... up to this time")->check(app::cli::utc_time());
  sub.add_option("--fit-months", args->fit_months,
                 "Fit only rows of these calendar months (UTC): e.g. 1-3, 12,1,2 or DJF,MAM")
      ->check(app::cli::month_list());
  sub.add_option("--test-months", args->test_months,
                 "Also report the MAPE on rows of these calendar months, e.g. 4-12")
      ->check(app::cli::month_list());
  sub.add_flag("--breakdown", args->breakdown,
               "Print the held-out (else fitting) window's MAPE and bias per month and region "
               "and per wind-speed bin, as Markdown tables");
  sub.add_option("--leave-one-out", args->leave_one_out,
                 "Also fit on all but one season (seasons: DJF, MAM, JJA, SON) or month "
                 "(months) of the --from/--to window and test on it, for each in turn")
      ->check(CLI::IsMember({"seasons", "months"}));
  sub.add_option(
         "--free", args->free,
         "What the fit frees besides the Cp surface: a list of table (a Cp(lambda) table "
         "instead of Heier's c1 and lambda_scale), loss (no-load loss), offset and gain "
         "(nacelle transfer function), yaw (yaw loss exponent), tracking-tsr and "
         "tracking-band (the tip-speed ratio the controller tracks and the speed band where "
         "the rotor speed gives the wind), turbulence (the wind's spread within a row), or "
         "none")
      ->default_val("table,loss,offset,gain,tracking-tsr,tracking-band,turbulence");
  sub.add_flag("--no-progress", args->no_progress, "No progress line on a terminal");
  sub.add_flag("--constant-density", args->constant_density,
               "Ignore an ambient temperature column: constant air_density_kg_m3");
  sub.add_option("--update", args->update,
                 "Replace the [turbine.cp] and [turbine.corrections] tables of this description "
                 "file with the fit");
  sub.callback([args] { run(*args); });
}

const bool kFitCpRegistered = app::cli::register_command(
    {"fit-cp", "Fit the Cp(lambda, beta) surface and SCADA corrections of a drivetrain description",
     &setup_fit_cp});

}  // namespace
