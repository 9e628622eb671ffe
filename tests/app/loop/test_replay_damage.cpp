// `drivetwin run --replay` of the built-in SCADA day gives the damage `drivetwin damage`
// gives on the same day, per gear and bearing channel, within 1 %: the first three
// 10-minute rows (two row changes) with the ROM at 4096 Hz (cut-off 1500 Hz). Native only
// (1800 s × 4096 steps). DRIVETWIN_REPLAY_ROWS=143 compares the whole day (docs/run.md).
#include <cstdlib>

#include "replay_damage_check.hpp"

namespace {

TEST(ReplayVsDamage, TheBuiltInDaysFirstRowsGiveDamagesPerChannelWithinOnePercent) {
  const char* rows = std::getenv("DRIVETWIN_REPLAY_ROWS");
  run_test::expect_replay_equals_damage(rows ? std::strtoul(rows, nullptr, 10) : 3, 64, 1500.0,
                                        0.01);
}

}  // namespace
