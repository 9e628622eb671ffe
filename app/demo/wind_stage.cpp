// Demo stage "wind load": the torque estimate on a built-in real day of Kelmarsh
// SCADA (app/data/kelmarsh-day.csv, 2019-12-05, a month not used for the Cp fit)
// with the built-in kelmarsh-mm92 description, compared on the electrical side with
// the measured P/ω (app/wind/torque_estimate.hpp).
#include <cmath>
#include <cstdio>
#include <string>

#include "cli/run.hpp"
#include "config/drivetrain_file.hpp"
#include "data/embedded.hpp"
#include "demo/demo.hpp"
#include "hal/scada_csv.hpp"
#include "wind/torque_estimate.hpp"

namespace {

using model::wind::OperatingRegion;

void run_wind_stage(const app::demo::DemoContext& ctx) {
  constexpr const char* kFile = "kelmarsh-day.csv";
  const auto text = app::data::embedded_file(kFile);
  if (!text) throw app::cli::CommandError(std::string("demo: built-in data ") + kFile + " missing");
  const model::Drivetrain drivetrain = app::config::load_drivetrain("kelmarsh-mm92");
  hal::ScadaCsvReader reader;
  if (!reader.open_text(*text, std::string("<built-in ") + kFile + ">",
                        hal::kelmarsh_scada_columns())) {
    throw app::cli::CommandError(reader.error());
  }
  const app::wind::TorqueEstimator estimator(drivetrain, true);
  const app::wind::TorqueSummary s =
      app::wind::run_torque(reader, estimator, app::wind::TimeWindow{}, {});

  auto rows = [&](OperatingRegion r) { return s.region_rows[static_cast<std::size_t>(r)]; };
  std::fprintf(ctx.out,
               "Kelmarsh turbine 1 (Senvion MM92), 2019-12-05, 10-min SCADA: %zu rows\n"
               "(Plumley 2022, doi:10.5281/zenodo.5841833, CC-BY-4.0)\n",
               s.rows);
  const model::TurbineCorrections& k = drivetrain.turbine.corrections;
  std::fprintf(ctx.out,
               "drivetrain %s: rated %.0f kN·m at %.2f rpm, Cp_max %.3f (at λ %.2f); the rotor's "
               "speed gives the wind at λ %.2f between %.2f and %.2f rpm, the anemometer at the "
               "limits; wind spread within a row %.1f %%\n",
               drivetrain.name.c_str(), drivetrain.turbine.rated_torque_nm / 1e3,
               drivetrain.turbine.rated_rotor_speed_rpm, estimator.load().cp_peak().cp_max,
               estimator.load().cp_peak().lambda_opt, k.tracking_tip_speed_ratio,
               (1.0 + k.tracking_band_margin) * drivetrain.turbine.min_rotor_speed_rpm,
               (1.0 - k.tracking_band_margin) * drivetrain.turbine.rated_rotor_speed_rpm,
               100.0 * k.turbulence_intensity);
  std::fprintf(ctx.out,
               "regions: below cut-in %zu, 2 (tracking) %zu, 2.5 (speed-limited) %zu, "
               "3 (rated) %zu, above cut-out %zu, stopped %zu\n",
               rows(OperatingRegion::kBelowCutIn), rows(OperatingRegion::kTracking),
               rows(OperatingRegion::kSpeedLimited), rows(OperatingRegion::kRated),
               rows(OperatingRegion::kAboveCutOut), rows(OperatingRegion::kStopped));
  if (s.max_torque_nm > 0.0) {
    std::fprintf(ctx.out, "rotor torque estimate: %.0f to %.0f kN·m\n", s.min_torque_nm / 1e3,
                 s.max_torque_nm / 1e3);
  }
  const auto& m = s.mape;
  std::fprintf(
      ctx.out,
      "MAPE of (η·T·ω − P0)/ω vs measured P/ω, η = %.2f, P0 = %.1f kW, air density from "
      "the ambient temperature in %zu rows, %zu rows in operation: region 2 %.1f %% (%zu), "
      "2.5 %.1f %% (%zu), 3 %.1f %% (%zu), all %.1f %%\n",
      drivetrain.turbine.drivetrain_efficiency, drivetrain.turbine.corrections.no_load_loss_w / 1e3,
      s.density_rows, m.count(), m.mape_pct(0), m.count(0), m.mape_pct(1), m.count(1),
      m.mape_pct(2), m.count(2), m.mape_pct());
  for (const auto& [reason, count] : s.excluded) {
    std::fprintf(ctx.out, "not counted: %zu rows, %s\n", count, reason.c_str());
  }
}

const bool kWindStageRegistered = app::demo::register_stage({10, "wind", &run_wind_stage});

}  // namespace
