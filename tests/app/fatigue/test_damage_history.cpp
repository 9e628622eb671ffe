// History mode: damage from SCADA rows through the load spectrum, bad-row handling.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "fatigue/damage_history.hpp"
#include "model/fatigue/damage_accumulator.hpp"

namespace {
namespace mf = model::fatigue;
using app::fatigue::HistoryResult;

struct HistoryBench {
  model::Drivetrain drivetrain = model::paper_2mw();
  mf::ChannelSet channels{drivetrain, mf::ChannelOptions{}};
  mf::LoadSpectrum spectrum;
  HistoryBench() {
    mf::SpectrumGrid g;
    g.torque_max_nm = 1.5 * drivetrain.turbine.rated_torque_nm;
    g.speed_max_rpm = 18.0;
    spectrum = mf::build_load_spectrum(channels, g, mf::SpectrumSource::kQuasiStatic,
                                       mf::quasi_static_simulator(channels), nullptr);
  }
  HistoryResult run(const std::string& csv, const std::string& name) {
    const std::string path = testing::TempDir() + name;
    std::ofstream(path) << csv;
    hal::ScadaCsvReader reader;
    EXPECT_TRUE(reader.open(path, hal::bundle_scada_columns())) << reader.error();
    return app::fatigue::run_history(reader, drivetrain, channels, spectrum, {});
  }
};

constexpr const char* kHeader = "t_s,wind_speed_mps,rotor_speed_rpm,power_kw,pitch_deg,torque_nm\n";

TEST(DamageHistory, ConstantRowsGiveRevolutionsTimesDamagePerRevolution) {
  // Arrange: 6 rows of 10 min at 14 rpm and 1.0e6 N·m: revs = 6·600·14/60 = 840.
  HistoryBench s;
  std::string csv = kHeader;
  for (int i = 0; i < 6; ++i) csv += std::to_string(600 * i) + ",10,14,,,1000000\n";
  // Act
  const HistoryResult h = s.run(csv, "constant.csv");
  // Assert: against the online accumulator fed the same quasi-static loads for 840 revs.
  mf::DamageAccumulator direct(s.channels, {});
  direct.step(s.channels.quasi_static_loads(1e6), 14.0, 3600000);  // 3600 s in 1 ms ticks
  EXPECT_EQ(h.rows_used, 6u);
  EXPECT_DOUBLE_EQ(h.period_s, 600.0);
  for (std::size_t c = 0; c < s.channels.channel_count(); ++c) {
    EXPECT_NEAR(h.damage[c], direct.damage(c), 1e-2 * direct.damage(c))
        << s.channels.channel(c).component;
  }
}

TEST(DamageHistory, BadRowsAreReportedWithRowAndFieldAndLeaveTheDamageOfTheGoodRows) {
  // Arrange: good rows 1, 2, 7 (after a gap) and bad rows between them.
  HistoryBench s;
  const std::string bad = std::string(kHeader) +
                          "0,10,14,,,1000000\n"     // 1 good
                          "600,10,14,,,1100000\n"   // 2 good
                          "600,10,14,,,1100000\n"   // 3 duplicate t_s
                          "300,10,14,,,1100000\n"   // 4 unsorted t_s
                          "1200,10,-5,,,1100000\n"  // 5 negative rotor speed
                          "1800,10,14,,,nan\n"      // 6 non-finite torque
                          "7200,10,14,,,900000\n";  // 7 good, after a gap
  const std::string good =
      std::string(kHeader) + "0,10,14,,,1000000\n600,10,14,,,1100000\n7200,10,14,,,900000\n";
  // Act
  const HistoryResult h = s.run(bad, "bad.csv");
  const HistoryResult ref = s.run(good, "good.csv");
  // Assert
  EXPECT_EQ(h.rows, 7u);
  EXPECT_EQ(h.rows_used, 3u);
  EXPECT_EQ(h.rows_rejected, 4u);
  EXPECT_EQ(h.rejected_time, 2u);
  EXPECT_EQ(h.rejected_speed, 1u);
  EXPECT_EQ(h.rejected_nonnumeric, 1u);
  EXPECT_EQ(h.gaps, 1u);
  ASSERT_GE(h.issues.size(), 5u);
  EXPECT_EQ(h.issues[0].row, 3u);
  EXPECT_EQ(h.issues[0].field, "t_s");
  EXPECT_NE(h.issues[0].message.find("duplicate"), std::string::npos);
  EXPECT_EQ(h.issues[1].row, 4u);
  EXPECT_EQ(h.issues[2].row, 5u);
  EXPECT_EQ(h.issues[2].field, "rotor_speed_rpm");
  EXPECT_NE(h.issues[3].message.find("row 6"), std::string::npos);
  EXPECT_NE(h.issues[3].message.find("torque_nm"), std::string::npos);
  EXPECT_EQ(h.issues[4].row, 7u);
  EXPECT_NE(h.issues[4].message.find("gap"), std::string::npos);
  for (std::size_t c = 0; c < s.channels.channel_count(); ++c)
    EXPECT_EQ(h.damage[c], ref.damage[c]);
}

TEST(DamageHistory, TorqueComesFromPowerOverSpeedWhenNoTorqueColumnIsGiven) {
  // P = 1466.08 kW at 14 rpm (ω = 1.466077 rad/s), η = 1: T = 1.0e6 N·m, as the first test.
  HistoryBench s;
  std::string by_power = kHeader, by_torque = kHeader;
  for (int i = 0; i < 3; ++i) {
    by_power += std::to_string(600 * i) + ",10,14,1466.0766,,\n";
    by_torque += std::to_string(600 * i) + ",10,14,,,1000000\n";
  }
  const HistoryResult hp = s.run(by_power, "power.csv");
  const HistoryResult ht = s.run(by_torque, "torque.csv");
  EXPECT_EQ(hp.torque_rows_power, 3u);
  for (std::size_t c = 0; c < s.channels.channel_count(); ++c) {
    EXPECT_NEAR(hp.damage[c], ht.damage[c], 1e-5 * ht.damage[c]);
  }
}

TEST(DamageHistory, PowerCountsTheNoLoadLossAndTheEfficiency) {
  // The power source is the project's one (app/wind/torque_source.hpp): with η = 0.94 and
  // P_0 = 47 356.126 W, P = 1000 kW at 14 rpm is T = (1e6 + 47 356.126)/0.94/1.4660766
  // = 759 993.49 N·m by hand, not P/(η·ω) = 725 630.44 N·m.
  HistoryBench s;
  s.drivetrain.turbine.drivetrain_efficiency = 0.94;
  s.drivetrain.turbine.corrections.no_load_loss_w = 47356.12631710944;
  std::string by_power = kHeader, by_torque = kHeader;
  for (int i = 0; i < 3; ++i) {
    by_power += std::to_string(600 * i) + ",10,14,1000,,\n";
    by_torque += std::to_string(600 * i) + ",10,14,,,759993.49\n";
  }
  const HistoryResult hp = s.run(by_power, "lossy-power.csv");
  const HistoryResult ht = s.run(by_torque, "lossy-torque.csv");
  EXPECT_EQ(hp.torque_rows_power, 3u);
  for (std::size_t c = 0; c < s.channels.channel_count(); ++c) {
    EXPECT_NEAR(hp.damage[c], ht.damage[c], 1e-6 * ht.damage[c]) << c;
  }
}

TEST(DamageHistory, AnImplausiblePowerRejectsTheRowByName) {
  // paper-2mw is rated 2 MW: 4 001 kW is beyond twice that.
  HistoryBench s;
  const HistoryResult h =
      s.run(std::string(kHeader) + "0,10,14,4001,,\n600,10,14,1000,,\n", "power-range.csv");
  EXPECT_EQ(h.rows_used, 1u);
  EXPECT_EQ(h.rejected_range, 1u);
  ASSERT_FALSE(h.issues.empty());
  EXPECT_EQ(h.issues[0].field, "power_kw");
  EXPECT_NE(h.issues[0].message.find("beyond twice the rated power"), std::string::npos);
}

}  // namespace
