// Held-out tests with the seasons in them (app/wind/heldout.hpp): calendar months from UTC
// times, month sets, the per-month × region breakdown against hand-computed errors, and a
// leave-one-season-out run on a synthetic year whose no-load loss differs in winter, where
// the winter fold's error is known by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include <unistd.h>

#include "config/drivetrain_file.hpp"
#include "hal/scada_csv.hpp"
#include "model/wind/wind_load.hpp"
#include "wind/cp_fit.hpp"
#include "wind/heldout.hpp"
#include "wind/torque_estimate.hpp"

namespace {

using app::wind::MonthSet;

double utc(const char* text) { return hal::parse_utc_datetime_s(text).value(); }

TEST(HeldOut, CalendarMonthOfUtcTimes) {
  EXPECT_EQ(app::wind::utc_month(0.0), 1);  // 1970-01-01
  EXPECT_EQ(app::wind::utc_month(utc("2019-01-01 00:00:00")), 1);
  EXPECT_EQ(app::wind::utc_month(utc("2019-02-28 23:59:59")), 2);
  EXPECT_EQ(app::wind::utc_month(utc("2019-03-01 00:00:00")), 3);
  EXPECT_EQ(app::wind::utc_month(utc("2019-12-05 12:00:00")), 12);
  EXPECT_EQ(app::wind::utc_month(utc("2019-12-31 23:59:59")), 12);
  EXPECT_EQ(app::wind::utc_month(utc("2020-02-29 12:00:00")), 2);  // leap day
  EXPECT_EQ(app::wind::utc_month(utc("2100-03-01 00:00:00")), 3);  // 2100 is not a leap year
}

TEST(HeldOut, MonthSetsParseListsRangesAndSeasons) {
  std::string error;
  const auto djf = MonthSet::parse("DJF", &error);
  ASSERT_TRUE(djf) << error;
  EXPECT_EQ(*djf, MonthSet::of({12, 1, 2}));
  EXPECT_EQ(*djf, MonthSet::parse("1-2, 12", &error).value());
  EXPECT_EQ(djf->label(), "Jan,Feb,Dec");
  const auto fit = MonthSet::parse("1-3", &error).value();
  const auto test = MonthSet::parse("4-12", &error).value();
  EXPECT_EQ(fit.complement(), test);
  EXPECT_EQ(fit.label(), "Jan-Mar");
  EXPECT_TRUE((fit & test).empty());
  EXPECT_EQ(MonthSet::parse("DJF,MAM,JJA,SON", &error).value(), MonthSet::all());
  // Four seasons partition the year.
  MonthSet none = MonthSet::of({});
  EXPECT_TRUE(none.empty());
  int months = 0;
  for (const auto& s : app::wind::meteorological_seasons()) {
    for (int m = 1; m <= 12; ++m) months += s.months.contains(m) ? 1 : 0;
  }
  EXPECT_EQ(months, 12);
  for (const char* bad : {"13", "0", "5-3", "", "JFM", "1-", "a"}) {
    EXPECT_FALSE(MonthSet::parse(bad, &error)) << bad;
    EXPECT_FALSE(error.empty()) << bad;
  }
  EXPECT_FALSE(MonthSet::parse("11-2", &error));
  EXPECT_NE(error.find("two: 11-12,1-2"), std::string::npos) << error;
}

app::wind::RowEstimate row_in(model::wind::OperatingRegion region, double compared,
                              double reference) {
  app::wind::RowEstimate e;
  e.in_operation = true;
  e.load.region = region;
  e.compared_torque_nm = compared;
  e.reference_torque_nm = reference;
  return e;
}

TEST(HeldOut, BreakdownByMonthRegionAndWindBinAgreesWithHandValues) {
  using R = model::wind::OperatingRegion;
  app::wind::ErrorBreakdown b;
  const double jan = utc("2019-01-03 10:00:00"), jul = utc("2019-07-02 03:10:00");
  b.add(jan, 3.5, row_in(R::kTracking, 110.0, 100.0));     // +10 %, low wind
  b.add(jan, 4.9, row_in(R::kTracking, 80.0, 100.0));      // −20 %, low wind
  b.add(jan, 9.0, row_in(R::kSpeedLimited, 99.0, 100.0));  // −1 %
  b.add(jul, 13.0, row_in(R::kRated, 102.0, 100.0));       // +2 %
  b.add(jul, 5.0, row_in(R::kTracking, 95.0, 100.0));      // −5 %, not in [3, 5)
  app::wind::RowEstimate out = row_in(R::kTracking, 300.0, 100.0);
  out.in_operation = false;  // ignored
  b.add(jul, 4.0, out);
  // Month × region
  EXPECT_EQ(b.cell(1, 0).rows, 2u);
  EXPECT_NEAR(b.cell(1, 0).mape_pct(), 15.0, 1e-12);  // (10 + 20)/2
  EXPECT_NEAR(b.cell(1, 0).bias_pct(), -5.0, 1e-12);  // (10 − 20)/2
  EXPECT_NEAR(b.cell(1, 1).mape_pct(), 1.0, 1e-12);
  EXPECT_NEAR(b.cell(7, 2).bias_pct(), 2.0, 1e-12);
  EXPECT_EQ(b.cell(7, 0).rows, 1u);
  EXPECT_TRUE(std::isnan(b.cell(2, 0).mape_pct()));
  // Totals
  EXPECT_NEAR(b.month_total(1).mape_pct(), 31.0 / 3.0, 1e-12);
  EXPECT_NEAR(b.region_total(0).mape_pct(), 35.0 / 3.0, 1e-12);  // 10, 20, 5
  EXPECT_NEAR(b.total().mape_pct(), 38.0 / 5.0, 1e-12);
  EXPECT_NEAR(b.total().bias_pct(), -14.0 / 5.0, 1e-12);
  // Low-wind band [3, 5) m/s and wind bins
  EXPECT_EQ(b.low_wind_total().rows, 2u);
  EXPECT_NEAR(b.low_wind(1).mape_pct(), 15.0, 1e-12);
  EXPECT_EQ(b.wind_bin(3).rows, 1u);
  EXPECT_EQ(b.wind_bin(4).rows, 1u);
  EXPECT_EQ(b.wind_bin(5).rows, 1u);
  EXPECT_NEAR(b.wind_bin(13).bias_pct(), 2.0, 1e-12);
  // The tables carry the numbers.
  EXPECT_NE(b.month_table().find("| Jan | 15.00 (2) | 1.00 (1) | – | 10.33 (3) |"),
            std::string::npos)
      << b.month_table();
  EXPECT_NE(b.wind_table().find("| 13–14 | 1 | 2.00 | +2.00 |"), std::string::npos)
      << b.wind_table();
}

constexpr double kRadPerRpm = 2.0 * std::numbers::pi / 60.0;

class LeaveOneOut : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("drivetwin_heldout_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

TEST_F(LeaveOneOut, TheWinterFoldCarriesExactlyTheWinterLossItWasNotFittedOn) {
  // Arrange: a year of rows from one turbine (the textbook surface, η = 0.94) near its
  // λ_opt at 5–8 m/s, whose no-load loss is 30 kW in December–February and 60 kW otherwise.
  model::Drivetrain d = app::config::load_drivetrain("kelmarsh-mm92");
  d.turbine.cp = app::wind::textbook_cp_surface();
  d.turbine.corrections = model::TurbineCorrections{};
  const model::wind::WindLoad load(d.turbine);
  const double lambda_opt = load.cp_peak().lambda_opt;
  const std::string path = (dir_ / "year.csv").string();
  std::ofstream out(path);
  out << "t_s,wind_speed_mps,rotor_speed_rpm,power_kw\n";
  std::vector<double> winter_power_w;
  for (int month = 1; month <= 12; ++month) {
    char date[32];
    std::snprintf(date, sizeof date, "2019-%02d-03 00:00:00", month);
    const double t0 = utc(date);
    const bool winter = month == 12 || month <= 2;
    const double p0 = winter ? 30e3 : 60e3;
    int i = 0;
    for (double v = 5.0; v < 8.0 + 1e-9; v += 0.1, ++i) {
      // Around λ_opt (±6 %), so that the surface's λ scale is identifiable.
      const double w = lambda_opt * (1.0 + 0.03 * (i % 5 - 2)) * v / d.turbine.rotor_radius_m;
      const double aero_w = load.with_rotor_speed(v, w, 0.0, false).torque_nm * w;
      const double p_w = d.turbine.drivetrain_efficiency * aero_w - p0;
      if (winter) winter_power_w.push_back(p_w);
      char line[160];
      std::snprintf(line, sizeof line, "%.0f,%.17g,%.17g,%.17g\n", t0 + 600.0 * i, v,
                    w / kRadPerRpm, p_w / 1e3);
      out << line;
    }
  }
  out.close();
  app::wind::FitOptions options;  // Heier c1 and λ scale
  options.no_load_loss = true;
  const app::wind::TimeWindow year;
  // Act
  const auto folds =
      app::wind::leave_one_out(path, hal::bundle_scada_columns(), d, app::wind::EstimatorOptions{},
                               year, app::wind::meteorological_seasons(), options);
  // Assert: the winter fold is fitted on 9 months at 60 kW, so each winter row is off by
  // −30 kW/P_i exactly (the estimate (ηTω − 60 kW)/ω against (ηTω − 30 kW)/ω).
  ASSERT_EQ(folds.size(), 4u);
  const auto& djf = folds[0];
  ASSERT_EQ(djf.name, "DJF");
  const std::size_t per_month = winter_power_w.size() / 3;
  EXPECT_EQ(djf.fit_rows, 9 * per_month);
  double mape = 0.0, bias = 0.0;
  for (double p : winter_power_w) {
    mape += 100.0 * 30e3 / p;
    bias -= 100.0 * 30e3 / p;
  }
  mape /= static_cast<double>(winter_power_w.size());
  bias /= static_cast<double>(winter_power_w.size());
  EXPECT_EQ(djf.breakdown.total().rows, winter_power_w.size());
  EXPECT_NEAR(djf.breakdown.total().mape_pct(), mape, 0.02);
  EXPECT_NEAR(djf.breakdown.total().bias_pct(), bias, 0.02);
  EXPECT_LT(djf.fit_mape_pct, 0.01);
  EXPECT_NEAR(djf.fit.corrections.no_load_loss_w, 60e3, 20.0)
      << "LM status " << djf.fit.lm_status << ", " << djf.fit.iterations << " iterations";
  EXPECT_EQ(djf.breakdown.month_total(3).rows, 0u);  // no other month leaks into the test
  // The other folds fit 60 kW on a 2:1 majority (L1) and test on 60 kW months.
  for (std::size_t f = 1; f < 4; ++f) {
    EXPECT_EQ(folds[f].fit_rows, 9 * per_month) << folds[f].name;
    EXPECT_LT(folds[f].breakdown.total().mape_pct(), 0.05) << folds[f].name;
  }
  EXPECT_NE(app::wind::leave_one_out_table(folds).find("| DJF (Jan,Feb,Dec) | "),
            std::string::npos);
}

}  // namespace
