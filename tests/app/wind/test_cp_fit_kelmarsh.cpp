// The committed kelmarsh-mm92 description against the real Kelmarsh data: it is
// what `fit-cp` produces on January–March 2019, and on the held-out months
// April–December (the seasons are in the test) it beats the textbook surface, meets the
// paper's 8.34 % and keeps region 3 within 5 %. Runs the full fit (a few
// seconds natively): NO_EMULATOR.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "config/drivetrain_file.hpp"
#include "hal/scada_csv.hpp"
#include "model/wind/cp_surface.hpp"
#include "wind/cp_fit.hpp"
#include "wind/heldout.hpp"
#include "wind/torque_estimate.hpp"

namespace {

const char* kKelmarsh = DRIVETWIN_SHARED_DIR "/data/kelmarsh/kelmarsh-t1-2019.csv";

struct Pass {
  app::wind::MapeAccumulator mape;
  std::vector<app::wind::FitRow> rows;
};

Pass run_kelmarsh(const model::Drivetrain& d, const char* months) {
  hal::ScadaCsvReader reader;
  EXPECT_TRUE(reader.open(kKelmarsh, hal::kelmarsh_scada_columns())) << reader.error();
  const app::wind::TorqueEstimator estimator(d, app::wind::EstimatorOptions{});
  app::wind::TimeWindow window;
  std::string error;
  window.months = app::wind::MonthSet::parse(months, &error).value().mask();
  Pass pass;
  const auto summary = app::wind::run_torque(
      reader, estimator, window, [&](const hal::ScadaRow& row, const app::wind::RowEstimate& e) {
        if (e.in_operation) pass.rows.push_back(app::wind::fit_row_of(row, e));
      });
  pass.mape = summary.mape;
  return pass;
}

TEST(CpFitKelmarsh, CommittedDescriptionIsWhatFitCpProducesOnJanuaryToMarch) {
  if (!std::filesystem::exists(kKelmarsh)) GTEST_SKIP() << "shared data absent: " << kKelmarsh;
  // Arrange
  const model::Drivetrain d = app::config::load_drivetrain("kelmarsh-mm92");
  const Pass train = run_kelmarsh(d, "1-3");
  app::wind::FitOptions options;  // fit-cp's default
  options.cp_table = options.no_load_loss = options.nacelle_offset = options.nacelle_gain = true;
  options.tracking_tsr = options.tracking_band = options.turbulence = true;
  // Act
  const app::wind::CpFitResult fit = app::wind::fit_cp_surface(d.turbine, train.rows, options);
  // Assert: the file holds the fit (to the digits a re-run on another CPU reproduces).
  for (std::size_t k = 0; k < model::kCpTableKnots; ++k) {
    EXPECT_NEAR(fit.surface.table_cp[k], d.turbine.cp.table_cp[k], 1e-5) << "knot " << k;
  }
  EXPECT_NEAR(fit.corrections.no_load_loss_w, d.turbine.corrections.no_load_loss_w, 1.0);
  EXPECT_NEAR(fit.corrections.nacelle_wind_gain, d.turbine.corrections.nacelle_wind_gain, 1e-5);
  EXPECT_NEAR(fit.corrections.nacelle_wind_offset_mps,
              d.turbine.corrections.nacelle_wind_offset_mps, 1e-5);
  EXPECT_NEAR(fit.corrections.tracking_tip_speed_ratio,
              d.turbine.corrections.tracking_tip_speed_ratio, 1e-5);
  EXPECT_NEAR(fit.corrections.tracking_band_margin, d.turbine.corrections.tracking_band_margin,
              1e-5);
  EXPECT_NEAR(fit.corrections.turbulence_intensity, d.turbine.corrections.turbulence_intensity,
              1e-5);
}

TEST(CpFitKelmarsh, FittedDescriptionBeatsTheTextbookSurfaceOnTheHeldOutMonths) {
  if (!std::filesystem::exists(kKelmarsh)) GTEST_SKIP() << "shared data absent: " << kKelmarsh;
  // Arrange
  const model::Drivetrain fitted = app::config::load_drivetrain("kelmarsh-mm92");
  model::Drivetrain textbook = fitted;
  textbook.turbine.cp = app::wind::textbook_cp_surface();
  textbook.turbine.corrections = model::TurbineCorrections{};
  // Act: April–December, not used for fitting.
  const Pass with_fit = run_kelmarsh(fitted, "4-12");
  const Pass without = run_kelmarsh(textbook, "4-12");
  const Pass train = run_kelmarsh(fitted, "1-3");
  // Assert: the fit helps out of sample and meets the paper's 8.34 % with the seasons in the
  // test (measured 6.13 % against 4.14 % in January–March; docs/wind.md).
  RecordProperty("heldout_mape_pct", std::to_string(with_fit.mape.mape_pct()));
  EXPECT_GT(with_fit.mape.count(), 6000u);
  EXPECT_LT(with_fit.mape.mape_pct(), without.mape.mape_pct());
  EXPECT_LT(with_fit.mape.mape_pct(), 8.34);
  EXPECT_LT(with_fit.mape.mape_pct(), train.mape.mape_pct() + 2.5);
  // Region 3 is rated torque held by the controller: within 5 % of P/ω.
  EXPECT_LT(with_fit.mape.mape_pct(2), 5.0);
  // Every knot of the committed table within the Betz limit.
  for (double knot : fitted.turbine.cp.table_cp) EXPECT_LE(knot, model::wind::kBetzLimit);
}

}  // namespace
