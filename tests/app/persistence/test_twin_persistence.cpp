// TwinPersistence across threads (app/persistence/twin_persistence.hpp), as `drivetwin run`
// uses it: the service thread adds RUL intervals while the persistence thread saves. Every
// saved record must hold a consistent rate history (its intervals add up to the damage at
// its last boundary), and a restart must see the last one. Labelled `threaded`: the TSan
// tier runs it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <numeric>
#include <thread>
#include <vector>

#include "model/drivetrain/description.hpp"
#include "model/fatigue/damage_accumulator.hpp"
#include "persistence/state_store.hpp"
#include "persistence/twin_persistence.hpp"
#include "persistence/twin_state.hpp"

namespace {

namespace fs = std::filesystem;
namespace fat = model::fatigue;
using namespace app::persistence;

TEST(TwinPersistence, IntervalsAddedWhileSavingAlwaysLeaveAConsistentRecord) {
  // Arrange
  const fs::path dir = fs::path(testing::TempDir()) / ("twin-threads-" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const model::Drivetrain d = model::paper_2mw();
  const fat::ChannelSet cs(d, {});
  fat::AccumulatorConfig cfg;
  const fat::DamageAccumulator acc(cs, cfg);
  TwinPersistence p({dir, "", 3600.0, 24}, cs, cfg);
  (void)p.load();
  constexpr int kIntervals = 600, kSaves = 12;
  std::atomic<bool> done{false};
  // Act: the service thread's intervals (channel c's damage grows by (c + 1)·1e-6 each) …
  std::thread service([&] {
    std::vector<double> damage(cs.channel_count(), 0.0);
    for (int i = 0; i < kIntervals; ++i) {
      for (std::size_t c = 0; c < damage.size(); ++c)
        damage[c] += 1e-6 * static_cast<double>(c + 1);
      (void)p.add_interval(damage);
    }
    done = true;
  });
  // … while the persistence thread saves, each record checked as a restart would read it.
  int saved = 0, consistent = 0;
  std::thread persistence([&] {
    for (int k = 0; k < kSaves || !done.load(); ++k) {
      std::string error;
      if (!p.save(acc.state(), k, &error)) continue;
      ++saved;
      StateStore s(dir, "twin-state");
      const StateLoad l = s.load();
      if (!l.record) continue;
      const auto t = decode_twin_state(*l.record, &error);
      if (!t || !t->rate) continue;
      bool ok = true;
      for (const auto& ch : t->rate->channels) {
        const double sum = std::accumulate(ch.increments.begin(), ch.increments.end(), 0.0);
        ok = ok && ch.total_intervals == ch.increments.size() &&
             std::abs(sum - ch.damage_at_boundary) <= 1e-9 * (1.0 + ch.damage_at_boundary);
      }
      consistent += ok;
    }
  });
  service.join();
  persistence.join();
  std::string error;
  ASSERT_TRUE(p.save(acc.state(), 99, &error)) << error;
  // Assert: every record consistent; the last holds every interval.
  EXPECT_GE(saved, kSaves);
  EXPECT_EQ(consistent, saved);
  TwinPersistence again({dir, "", 3600.0, 24}, cs, cfg);
  const TwinLoad l = again.load();
  EXPECT_TRUE(l.restored);
  StateStore s(dir, "twin-state");
  const auto t = decode_twin_state(*s.load().record, &error);
  ASSERT_TRUE(t && t->rate);
  EXPECT_EQ(t->rate->channels.back().total_intervals, static_cast<std::uint64_t>(kIntervals));
  EXPECT_NEAR(t->rate->channels.back().damage_at_boundary,
              kIntervals * 1e-6 * static_cast<double>(cs.channel_count()), 1e-12);
  fs::remove_all(dir);
}

}  // namespace
