// The results snapshot's conversion to the register values (app/loop/snapshot.hpp).
#include <gtest/gtest.h>

#include <cmath>

#include "loop/snapshot.hpp"

namespace {

using app::loop::Snapshot;

TEST(Snapshot, RegisterValuesTakeTheWorsePointsFitAndEveryUsedChannel) {
  // Arrange
  Snapshot s;
  s.sequence = 7;
  s.stamp_ns = 1'500'000'000;
  s.status_word = app::results::kStatusRunning | app::results::kStatusDegraded;
  s.rotor_torque_nm = 361747.0f;
  s.points[0].rms_mps2 = 1.5f;
  s.points[1].kurtosis = 3.2f;
  s.fit[0] = {0.1f, 0.5f, NAN};
  s.fit[1] = {0.3f, 0.2f, 0.4f};
  s.channel_count = 2;
  s.channels[0].damage = 1e-4f;
  s.channels[1].rul_h = 2.0e5f;
  s.channels[2].damage = 9.0f;  // beyond channel_count: not shown
  // Act
  const app::results::ResultsValues v = app::loop::to_results_values(s);
  // Assert
  EXPECT_EQ(v.sequence, 7u);
  EXPECT_EQ(v.stamp_ns, 1'500'000'000);
  EXPECT_EQ(v.status_word, s.status_word);
  EXPECT_EQ(v.rotor_torque_nm, 361747.0f);
  EXPECT_EQ(v.indicators[0], 1.5f);
  EXPECT_TRUE(std::isnan(v.indicators[1]));  // no value is NaN, not 0
  EXPECT_EQ(v.indicators[3], 3.2f);
  EXPECT_EQ(v.indicators[5], 0.3f);
  EXPECT_EQ(v.indicators[6], 0.5f);
  EXPECT_EQ(v.indicators[7], 0.4f);  // one point without a value: the other's
  EXPECT_EQ(v.channels[0].damage, 1e-4f);
  EXPECT_EQ(v.channels[1].rul_h, 2.0e5f);
  EXPECT_EQ(v.channels[2].damage, 0.0f);
}

}  // namespace
