// `drivetwin torque <scada.csv>`: rotor input torque and operating region for
// every SCADA row (wind load model, model/wind), optionally compared with the
// measured torque or, on the electrical side, with P/ω as MAPE per operating
// region (app/wind/torque_estimate.hpp defines the reference and which rows count).
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "cli/command.hpp"
#include "cli/wind_options.hpp"
#include "config/drivetrain_file.hpp"
#include "hal/scada_csv.hpp"
#include "wind/heldout.hpp"
#include "wind/torque_estimate.hpp"

namespace {

using app::wind::ReferenceKind;

struct TorqueArgs {
  std::string file;
  std::string drivetrain;
  std::string columns = "bundle";
  std::string from;
  std::string to;
  std::string months;
  bool breakdown = false;
  bool compare = false;
  bool json = false;
  bool no_rows = false;
  bool steady_state = false;
};

nlohmann::json number_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nullptr; }

void run(const TorqueArgs& args) {
  const model::Drivetrain drivetrain = app::config::load_drivetrain(args.drivetrain);
  std::string error;
  const auto columns = hal::parse_scada_columns(args.columns, &error);
  if (!columns) throw app::cli::CommandError("--columns: " + error);
  app::wind::TimeWindow window;
  if (!args.from.empty()) window.from_s = app::wind::parse_time_option("--from", args.from);
  if (!args.to.empty()) window.to_s = app::wind::parse_time_option("--to", args.to);
  if (!args.months.empty()) {
    const auto set = app::wind::MonthSet::parse(args.months, &error);
    if (!set) throw app::cli::CommandError("--months: " + error);
    window.months = set->mask();
  }
  app::wind::ErrorBreakdown breakdown;

  hal::ScadaCsvReader reader;
  if (!reader.open(args.file, *columns)) throw app::cli::CommandError(reader.error());
  app::wind::EstimatorOptions options;
  options.measured_speed = !args.steady_state;
  const app::wind::TorqueEstimator estimator(drivetrain, options);
  const double eta = drivetrain.turbine.drivetrain_efficiency;

  bool first = true;
  if (args.json) {
    std::printf("{\"drivetrain\":%s,\"file\":%s,\"rows\":[",
                nlohmann::json(drivetrain.name).dump().c_str(),
                nlohmann::json(args.file).dump().c_str());
  } else if (!args.no_rows) {
    std::printf("# drivetrain %s; torque = rotor (low-speed shaft) input torque [N·m]\n",
                drivetrain.name.c_str());
    std::printf(
        "# with --compare: estimate_nm = the estimate on the reference's side (see summary)\n");
    std::printf("%8s %14s %9s %9s %13s %12s %12s %12s %9s\n", "row", "t_s", "wind_mps", "rotor_rpm",
                "region", "torque_nm", "estimate_nm", "reference_nm", "error_pct");
  }
  auto on_row = [&](const hal::ScadaRow& row, const app::wind::RowEstimate& e) {
    if (args.breakdown) {
      breakdown.add(row.time_s(), row.get(hal::ScadaQuantity::kWindSpeed), e);
    }
    if (args.no_rows) return;
    const bool has_ref = e.reference != ReferenceKind::kNone;
    const double err_pct = has_ref && e.reference_torque_nm != 0.0
                               ? 100.0 * (e.compared_torque_nm - e.reference_torque_nm) /
                                     std::fabs(e.reference_torque_nm)
                               : std::nan("");
    if (args.json) {
      nlohmann::json j{
          {"row", row.row},
          {"t_s", number_or_null(row.time_s())},
          {"wind_speed_mps", number_or_null(row.get(hal::ScadaQuantity::kWindSpeed))},
          {"rotor_speed_rpm", number_or_null(row.get(hal::ScadaQuantity::kRotorSpeed))},
          {"region", e.estimated ? model::wind::region_name(e.load.region) : "no_wind_speed"},
          {"torque_nm", e.estimated ? nlohmann::json(e.load.torque_nm) : nlohmann::json(nullptr)}};
      if (args.compare) {
        j["reference_nm"] = has_ref ? nlohmann::json(e.reference_torque_nm) : nullptr;
        j["estimate_nm"] = has_ref ? nlohmann::json(e.compared_torque_nm) : nullptr;
        j["in_operation"] = e.in_operation;
        if (!e.in_operation) j["excluded_because"] = e.excluded_because;
      }
      std::printf("%s%s", first ? "\n" : ",\n", j.dump().c_str());
    } else {
      // No wind speed: no estimate, and no region (a turning rotor is not below cut-in).
      std::printf("%8zu %14.0f %9.3f %9.3f %13s %12s", row.row, row.time_s(),
                  row.get(hal::ScadaQuantity::kWindSpeed), row.get(hal::ScadaQuantity::kRotorSpeed),
                  e.estimated ? model::wind::region_name(e.load.region) : "no_wind_speed",
                  e.estimated ? std::to_string(std::lround(e.load.torque_nm)).c_str() : "-");
      if (args.compare && has_ref) {
        std::printf(" %12.0f %12.0f %9.2f%s", e.compared_torque_nm, e.reference_torque_nm, err_pct,
                    e.in_operation ? "" : "  (not counted)");
      }
      std::printf("\n");
    }
    first = false;
  };

  app::wind::TorqueSummary summary;
  try {
    summary = app::wind::run_torque(reader, estimator, window, on_row);
  } catch (const std::runtime_error& e) {
    if (args.json) std::printf("]}\n");
    std::fflush(stdout);
    throw app::cli::CommandError(e.what());
  }
  // Rejected rows (app/wind/scada_rows.hpp): skipped, named on stderr, exit 2; the result
  // covers the other rows.
  const app::wind::RowRejections& rejected = summary.rejected;
  if (rejected.rows_rejected > 0) {
    rejected.print(stderr, "drivetwin torque: ");
    app::cli::exit_status() = 2;
  }

  const auto& m = summary.mape;
  if (args.json) {
    std::printf("\n]");
    if (rejected.rows_rejected > 0) {
      nlohmann::json j{
          {"rows", rejected.rows_rejected},   {"nonnumeric", rejected.rejected_nonnumeric},
          {"speed", rejected.rejected_speed}, {"wind", rejected.rejected_wind},
          {"range", rejected.rejected_range}, {"issues", nlohmann::json::array()}};
      for (const auto& i : rejected.issues)
        j["issues"].push_back({{"row", i.row}, {"field", i.field}, {"message", i.message}});
      std::printf(",\"rejected\":%s", j.dump().c_str());
    }
    if (args.compare) {
      nlohmann::json s{{"rows", summary.rows},
                       {"rows_in_operation", m.count()},
                       {"reference", summary.measured_torque_rows > 0 ? "torque_nm" : "P/omega"},
                       {"drivetrain_efficiency", eta},
                       {"no_load_loss_w", drivetrain.turbine.corrections.no_load_loss_w},
                       {"density_from_temperature_rows", summary.density_rows},
                       {"mape_pct", number_or_null(m.mape_pct())}};
      for (std::size_t r = 0; r < m.kRegions; ++r) {
        s["regions"][app::wind::MapeAccumulator::region_label(r)] = {
            {"rows", m.count(r)}, {"mape_pct", number_or_null(m.mape_pct(r))}};
      }
      for (const auto& [reason, count] : summary.excluded) s["excluded"][reason] = count;
      std::printf(",\"summary\":%s", s.dump().c_str());
    }
    std::printf("}\n");
    return;
  }
  if (!args.compare) return;
  std::printf("\n# %s: %zu rows (%zu rejected, see stderr); estimate uses %s\n",
              reader.path().c_str(), summary.rows, rejected.rows_rejected,
              args.steady_state
                  ? "the controller's steady-state speed (--steady-state)"
                  : "measured rotor speed where present (pitch: curtailment filter only)");
  if (summary.measured_torque_rows + summary.power_rows == 0) {
    std::printf(
        "# no reference: the file has neither torque_nm nor power_kw with rotor_speed_rpm\n");
    return;
  }
  std::printf("# reference: %s", summary.measured_torque_rows > 0 ? "measured torque_nm" : "");
  if (summary.power_rows > 0) {
    std::printf(
        "%smeasured P/omega, against the estimate (eta*T*omega - P0)/omega, eta = %.3f, "
        "P0 = %.1f kW",
        summary.measured_torque_rows > 0 ? " and " : "", eta,
        drivetrain.turbine.corrections.no_load_loss_w / 1e3);
  }
  std::printf("\n# air density: ");
  if (summary.density_rows > 0) {
    std::printf("from the ambient temperature in %zu rows (ISA pressure at %.0f m)%s",
                summary.density_rows, drivetrain.turbine.site_altitude_m,
                summary.density_rows < summary.rows ? ", else constant" : "");
  } else {
    std::printf("constant %.3f kg/m3 (no ambient temperature column or values)",
                drivetrain.turbine.air_density_kg_m3);
  }
  if (summary.yaw_rows > 0) {
    std::printf("; yaw error used in %zu rows (cos^%.2f)", summary.yaw_rows,
                drivetrain.turbine.corrections.yaw_loss_exponent);
  }
  std::printf("\n# MAPE over rows in operation (app/wind/torque_estimate.hpp):\n");
  std::printf("%-8s %8s %9s\n", "region", "rows", "MAPE_pct");
  for (std::size_t r = 0; r < m.kRegions; ++r) {
    std::printf("%-8s %8zu %9.2f\n", app::wind::MapeAccumulator::region_label(r), m.count(r),
                m.mape_pct(r));
  }
  std::printf("%-8s %8zu %9.2f\n", "all", m.count(), m.mape_pct());
  for (const auto& [reason, count] : summary.excluded) {
    std::printf("# not counted: %zu rows, %s\n", count, reason.c_str());
  }
  if (args.breakdown) {
    std::printf("# per month and region:\n%s# per wind-speed bin (nacelle wind):\n%s",
                breakdown.month_table().c_str(), breakdown.wind_table().c_str());
  }
}

void setup_torque(CLI::App& sub) {
  auto args = std::make_shared<TorqueArgs>();
  sub.add_option("scada_csv", args->file,
                 "SCADA CSV (recording bundle scada.csv or a mapped export)")
      ->required();
  app::config::add_drivetrain_option(sub, args->drivetrain);
  sub.add_option("--columns", args->columns,
                 "Column mapping: bundle (default), kelmarsh, or 'field=Column;...' with field in "
                 "t_s, wind_speed_mps, rotor_speed_rpm, power_kw, pitch_deg, torque_nm, "
                 "ambient_temperature_c, yaw_error_deg");
  sub.add_flag("--compare", args->compare,
               "MAPE per operating region against measured torque_nm, else measured P/omega");
  sub.add_flag("--json", args->json, "Machine-readable output");
  sub.add_flag("--no-rows", args->no_rows, "Print only the --compare summary");
  sub.add_flag("--steady-state", args->steady_state,
               "Ignore measured rotor speed and pitch; use the controller's steady state");
  sub.add_option("--from", args->from,
                 "Only rows at or after this UTC time (YYYY-MM-DD[ HH:MM:SS])")
      ->check(app::cli::utc_time());
  sub.add_option("--to", args->to, "Only rows before this UTC time")->check(app::cli::utc_time());
  sub.add_option("--months", args->months,
                 "Only rows of these calendar months (UTC): e.g. 4-12, 12,1,2 or JJA,SON")
      ->check(app::cli::month_list());
  sub.add_flag("--breakdown", args->breakdown,
               "With --compare: MAPE and bias per month and region and per wind-speed bin, as "
               "Markdown tables");
  sub.callback([args] { run(*args); });
}

const bool kTorqueRegistered = app::cli::register_command(
    {"torque", "Estimate rotor input torque and operating region from SCADA wind speed",
     &setup_torque});

}  // namespace
