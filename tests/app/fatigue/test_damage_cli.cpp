// `drivetwin damage` end to end, in-process: the --json summary parsed with nlohmann-json
// and checked against the text table and a hand value; --per-day's distribution; the
// progress bar only on a terminal; the spectrum cache key's code version.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "fatigue/damage_history.hpp"
#include "fatigue/spectrum_cache.hpp"
#include "model/fatigue/drivetrain_channels.hpp"
#include "support/run_command.hpp"

namespace {
namespace fs = std::filesystem;
namespace mf = model::fatigue;

using test_support::CommandResult;
using test_support::run_command;

class DamageCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           (std::string("drivetwin_damage_") +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

// The damage column of the text table's row for (component, mode).
double table_damage(const std::string& out, const std::string& component, const std::string& mode) {
  std::istringstream in(out);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream f(line);
    std::string c, detail, m;
    double d = 0.0;
    if (f >> c >> detail >> m >> d && c == component && m == mode) return d;
  }
  ADD_FAILURE() << "no row " << component << " " << mode << " in\n" << out;
  return 0.0;
}

TEST_F(DamageCli, JsonSummaryAgreesWithTheTextTableAndTheHandValue) {
  // Arrange: two UTC days of 10-min rows at rated torque 1.23e6 N·m and 14 rpm; the wind column
  // (not used: the torque is measured) says 12 m/s the first day and 6.8 m/s the second.
  std::string csv = "t_s,wind_speed_mps,rotor_speed_rpm,power_kw,pitch_deg,torque_nm\n";
  for (int i = 0; i < 288; ++i)
    csv += std::to_string(600 * i) + (i < 144 ? ",12" : ",6.8") + ",14,,,1230000\n";
  const fs::path scada = dir_ / "scada.csv", json = dir_ / "summary.json";
  std::ofstream(scada) << csv;
  // Act
  const CommandResult r = run_command({"damage", scada.string(), "--json", json.string(),
                                       "--per-day", "--cache-dir", (dir_ / "cache").string()});
  // Assert
  ASSERT_EQ(r.exit_code, 0) << r.error;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["format"], "drivetwin-damage/1");
  EXPECT_EQ(j["rows"]["total"], 288);
  EXPECT_EQ(j["rows"]["used"], 288);
  EXPECT_DOUBLE_EQ(j["covered_s"].get<double>(), 288 * 600.0);
  EXPECT_EQ(j["rating"]["k_h_beta"], "iso6336-1-method-c");
  EXPECT_EQ(j["rating"]["contact_pattern"], "unverified");
  // b1 at the reference's catalogue C (1 700 kN), ISO 281's rating from its geometry beside it:
  // the hand calculation of tests/model/fatigue/test_bearing_rating.cpp (871 564.5 N at L_we =
  // 40 mm) times (60/40)^(7/9) for the reference's L_we = 60 mm = 1 194 701.5 N.
  EXPECT_NEAR(j["rating"]["bearing_c_n"]["b1"].get<double>(), 1.7e6, 1e-6);
  const nlohmann::json& b1 = j["rating"]["bearing_life"]["bearings"]["b1"];
  EXPECT_EQ(b1["c_source"], "description");
  EXPECT_NEAR(b1["c_iso281_geometry_n"].get<double>(), 1194701.5, 1.0);
  EXPECT_EQ(j["rating"]["bearing_life"]["life_modification"]["enabled"], true);
  EXPECT_GT(b1["a_iso_at_rated"].get<double>(), 0.0);
  const nlohmann::json* sun = nullptr;
  for (const auto& c : j["channels"]) {
    if (c["component"] == "sun" && c["mode"] == "contact") sun = &c;
  }
  ASSERT_NE(sun, nullptr);
  const double d_json = (*sun)["damage"].get<double>();
  // Text table prints 5 significant digits.
  EXPECT_NEAR(table_damage(r.out, "sun", "contact"), d_json, 1e-4 * d_json);
  // Hand value, independent of the spectrum and history code: rotor revolutions
  // 2 days·86 400 s·14/60 = 40 320; the sun meets 3 planets, z_r/z_s = 99/21 cycles per rotor
  // revolution each, at the stress of the quasi-static rated mesh force; D = n/N(σ).
  const mf::ChannelSet cs(model::paper_2mw(), mf::ChannelOptions{});
  std::size_t c_sun = 0;
  while (!(cs.channel(c_sun).component == "sun" &&
           cs.channel(c_sun).mode == mf::FailureMode::kContact))
    ++c_sun;
  const double sigma = cs.stress(c_sun, 0, cs.quasi_static_loads(1.23e6));
  const double hand =
      40320.0 * 3.0 * 99.0 / 21.0 / cs.channel(c_sun).curve.cycles_to_failure(sigma);
  EXPECT_NEAR(d_json, hand, 1e-9 * hand);
  EXPECT_NEAR((*sun)["damage_per_day"].get<double>(), hand / 2.0, 1e-9 * hand);
  // --per-day: two full days with the same damage, half the total each.
  EXPECT_EQ(j["per_day"]["full_days"], 2);
  EXPECT_NEAR(j["per_day"]["median"].get<double>(), hand / 2.0, 1e-9 * hand);
  // The days at the paper's check point (6.75 ± 0.1 m/s): the second day only.
  const auto& band = j["per_day"]["paper_wind_band"];
  EXPECT_EQ(band["days"], 1);
  EXPECT_DOUBLE_EQ(band["wind_mps"].get<double>(), 6.75);
  EXPECT_NEAR(band["median"].get<double>(), hand / 2.0, 1e-9 * hand);
}

TEST_F(DamageCli, ASpectrumCachedByAnOlderCodeVersionIsNotReused) {
  // Arrange: a spectrum stored under the current code version.
  const model::Drivetrain d = model::paper_2mw();
  const mf::ChannelSet cs(d, mf::ChannelOptions{});
  mf::SpectrumGrid g;
  g.torque_max_nm = 1.5 * d.turbine.rated_torque_nm;
  g.speed_max_rpm = 18.0;
  g.torque_points = 5;
  g.speed_points = 3;
  const mf::LoadSpectrum built = mf::build_load_spectrum(cs, g, mf::SpectrumSource::kQuasiStatic,
                                                         mf::quasi_static_simulator(cs), nullptr);
  const auto key_now = app::fatigue::spectrum_key(d, cs, g, mf::SpectrumSource::kQuasiStatic);
  const auto key_old = app::fatigue::spectrum_key(d, cs, g, mf::SpectrumSource::kQuasiStatic,
                                                  app::fatigue::kSpectrumCodeVersion - 1);
  const fs::path file_old = app::fatigue::spectrum_cache_file(dir_, key_old);
  ASSERT_TRUE(app::fatigue::store_cached_spectrum(file_old, key_old, built));
  // Act: the current code looks for its own key, also in the old file under its name.
  mf::LoadSpectrum s;
  s.grid = g;
  const bool hit_own_file = app::fatigue::load_cached_spectrum(
      app::fatigue::spectrum_cache_file(dir_, key_now), key_now, cs.channel_count(), s);
  const bool hit_old_file =
      app::fatigue::load_cached_spectrum(file_old, key_now, cs.channel_count(), s);
  const bool same_version_hits =
      app::fatigue::load_cached_spectrum(file_old, key_old, cs.channel_count(), s);
  // Assert
  EXPECT_NE(key_now, key_old);
  EXPECT_NE(app::fatigue::spectrum_cache_file(dir_, key_now), file_old);
  EXPECT_FALSE(hit_own_file);
  EXPECT_FALSE(hit_old_file);
  EXPECT_TRUE(same_version_hits);
}

TEST_F(DamageCli, ChangedRatingOptionsChangeTheCacheKey) {
  const model::Drivetrain d = model::paper_2mw();
  mf::ChannelOptions o;
  const mf::ChannelSet a(d, o);
  o.rating.face_load.lead = mf::LeadModification::kCrowning;
  const mf::ChannelSet b(d, o);
  mf::SpectrumGrid g;
  g.torque_max_nm = 1.8e6;
  g.speed_max_rpm = 18.0;
  EXPECT_NE(app::fatigue::spectrum_key(d, a, g, mf::SpectrumSource::kQuasiStatic),
            app::fatigue::spectrum_key(d, b, g, mf::SpectrumSource::kQuasiStatic));
  o.rating.face_load.contact_pattern_verified = true;
  const mf::ChannelSet c(d, o);
  EXPECT_NE(app::fatigue::spectrum_key(d, b, g, mf::SpectrumSource::kQuasiStatic),
            app::fatigue::spectrum_key(d, c, g, mf::SpectrumSource::kQuasiStatic));
}

TEST_F(DamageCli, BadFaceLoadOptionsAreRefusedWithTheOptionNamed) {
  const fs::path scada = dir_ / "s.csv";
  std::ofstream(scada) << "t_s,torque_nm,rotor_speed_rpm\n0,1000000,14\n600,1000000,14\n";
  const CommandResult lead = run_command({"damage", scada.string(), "--lead", "barrel"});
  EXPECT_EQ(lead.exit_code, 1);
  EXPECT_THAT(lead.error, testing::HasSubstr("--lead: 'barrel'"));
  const CommandResult khb = run_command({"damage", scada.string(), "--k-h-beta", "0.8"});
  EXPECT_NE(khb.exit_code, 0);  // refused while parsing (app/cli/options.hpp): CLI11's status
  EXPECT_THAT(khb.error, testing::HasSubstr("--k-h-beta: 0.8 is out of range; expected 0 (ISO "
                                            "6336-1 method C) or a number in [1, 10]"));
  const CommandResult pattern =
      run_command({"damage", scada.string(), "--contact-pattern", "maybe"});
  EXPECT_EQ(pattern.exit_code, 1);
  EXPECT_THAT(pattern.error, testing::HasSubstr("--contact-pattern: 'maybe'"));
}

}  // namespace
