// `drivetwin fit-cp <scada.csv>`: fits the Cp(λ, β) surface of a drivetrain
// description to SCADA rows in operation (method: app/wind/cp_fit.hpp), prints
// the fitted [turbine.cp] table and, with --update FILE, writes it into FILE.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "cli/command.hpp"
#include "config/drivetrain_file.hpp"
#include "hal/scada_csv.hpp"
#include "model/wind/cp_surface.hpp"
#include "wind/cp_fit.hpp"
#include "wind/torque_estimate.hpp"

namespace {

struct FitArgs {
  std::string file;
  std::string drivetrain;
  std::string columns = "bundle";
  std::string from;
  std::string to;
  std::string update;
};

app::wind::TorqueSummary evaluate(const FitArgs& args, const hal::ScadaColumns& columns,
                                  const model::Drivetrain& d, const app::wind::TimeWindow& window,
                                  std::vector<app::wind::FitRow>* rows) {
  hal::ScadaCsvReader reader;
  if (!reader.open(args.file, columns)) throw app::cli::CommandError(reader.error());
  const app::wind::TorqueEstimator estimator(d, true);
  constexpr double kRpm = 2.0 * std::numbers::pi / 60.0;
  try {
    return app::wind::run_torque(
        reader, estimator, window, [&](const hal::ScadaRow& row, const app::wind::RowEstimate& e) {
          if (rows == nullptr || !e.in_operation) return;
          rows->push_back({row.get(hal::ScadaField::kWindSpeed),
                           row.get(hal::ScadaField::kRotorSpeed) * kRpm,
                           0.0, false, e.reference_torque_nm});  // pitch: see TorqueEstimator
        });
  } catch (const std::runtime_error& e) {
    throw app::cli::CommandError(e.what());
  }
}

void print_mape(const char* label, const app::wind::MapeAccumulator& m) {
  std::printf("%s MAPE: region 2 %.2f %% (%zu rows), 2.5 %.2f %% (%zu), 3 %.2f %% (%zu), all %.2f %% (%zu)\n",
              label, m.mape_pct(0), m.count(0), m.mape_pct(1), m.count(1), m.mape_pct(2),
              m.count(2), m.mape_pct(), m.count());
}

void run(const FitArgs& args) {
  model::Drivetrain d = app::config::load_drivetrain(args.drivetrain);
  std::string error;
  const auto columns = hal::parse_scada_columns(args.columns, &error);
  if (!columns) throw app::cli::CommandError("--columns: " + error);
  app::wind::TimeWindow window;
  if (!args.from.empty()) window.from_s = app::wind::parse_time_option("--from", args.from);
  if (!args.to.empty()) window.to_s = app::wind::parse_time_option("--to", args.to);

  std::vector<app::wind::FitRow> rows;
  evaluate(args, *columns, d, window, &rows);
  const app::wind::CpFitResult fit = app::wind::fit_cp_surface(d.turbine, rows);
  d.turbine.cp = fit.surface;
  const model::wind::CpPeak peak = model::wind::find_cp_peak(fit.surface);

  std::printf("# fit-cp %s (%s .. %s), drivetrain %s, %zu rows in operation\n", args.file.c_str(),
              args.from.empty() ? "start" : args.from.c_str(), args.to.empty() ? "end" : args.to.c_str(),
              d.name.c_str(), fit.rows);
  std::printf("# Levenberg-Marquardt status %d after %d iterations; mean |relative torque error| "
              "%.4f (textbook start) -> %.4f\n",
              fit.lm_status, fit.iterations, fit.mean_abs_relative_error_before, fit.mean_abs_relative_error_after);
  std::printf("# fitted surface: Cp_max %.4f at lambda_opt %.3f (beta = 0)\n", peak.cp_max,
              peak.lambda_opt);
  const auto summary = evaluate(args, *columns, d, window, nullptr);
  print_mape("# fitting window", summary.mape);
  const std::string table = app::wind::cp_table_toml(fit.surface);
  std::printf("%s", table.c_str());

  if (!args.update.empty()) {
    std::ifstream in(args.update, std::ios::binary);
    if (!in) throw app::cli::CommandError(args.update + ": cannot read");
    std::stringstream text;
    text << in.rdbuf();
    const std::string updated = app::wind::replace_cp_table(text.str(), table, args.update);
    in.close();
    // Check the result still parses before overwriting.
    (void)app::config::parse_drivetrain(updated, args.update);
    std::ofstream out(args.update, std::ios::binary | std::ios::trunc);
    out << updated;
    if (!out) throw app::cli::CommandError(args.update + ": cannot write");
    std::printf("# wrote [turbine.cp] into %s\n", args.update.c_str());
  }
}

void setup(CLI::App& sub) {
  auto args = std::make_shared<FitArgs>();
  sub.add_option("scada_csv", args->file, "SCADA CSV with wind, rotor speed, pitch and power")
      ->required();
  app::config::add_drivetrain_option(sub, args->drivetrain);
  sub.add_option("--columns", args->columns, "Column mapping: bundle, kelmarsh or 'field=Column;...'");
  sub.add_option("--from", args->from, "Fit rows at or after this UTC time (YYYY-MM-DD[ HH:MM:SS])");
  sub.add_option("--to", args->to, "Fit rows before this UTC time");
  sub.add_option("--update", args->update,
                 "Replace the [turbine.cp] table of this description file with the fit");
  sub.callback([args] { run(*args); });
}

const bool kRegistered = app::cli::register_command(
    {"fit-cp", "Fit the Cp(lambda, beta) surface of a drivetrain description to SCADA", &setup});

}  // namespace
