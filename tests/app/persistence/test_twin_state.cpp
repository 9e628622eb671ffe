// The twin's state as state-record sections (app/persistence/twin_state.hpp): a round trip
// through the crash-safe store restores the accumulators bit for bit; a change of ROM rate,
// of bins and full scale, or of the channel set carries every channel's lifetime damage over
// (matched by key), keeps histogram totals, retires what the configuration lost and takes it
// back when it returns; the RUL rate history survives; a damaged section is named.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include "model/drivetrain/description.hpp"
#include "model/fatigue/damage_accumulator.hpp"
#include "model/fatigue/drivetrain_channels.hpp"
#include "model/fatigue/rul.hpp"
#include "persistence/state_store.hpp"
#include "persistence/twin_state.hpp"

namespace {

namespace fs = std::filesystem;
namespace fat = model::fatigue;
using namespace app::persistence;

fs::path fresh_twin_dir(const std::string& name) {
  const fs::path d =
      fs::path(testing::TempDir()) / ("twin-" + name + "-" + std::to_string(getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// Some operating history: torques 20–110 % of rated with per-mesh variation, `steps` steps
// of `dt_ticks` at 14 rpm.
void run(fat::DamageAccumulator& acc, int steps, std::uint32_t dt_ticks, int seed = 0) {
  const fat::ChannelSet& cs = acc.channels();
  for (int k = 0; k < steps; ++k) {
    const double u = 0.2 + 0.9 * (0.5 + 0.5 * std::sin(0.01 * (k + 37 * seed)));
    fat::LoadSample l = cs.quasi_static_loads(u * 1.23e6);
    for (std::size_t m = 0; m < cs.mesh_count(); ++m)
      l.mesh_force_n[m] *= 1.0 + 0.2 * std::sin(0.7 * k + m);
    (void)acc.step(l, 14.0, dt_ticks);
  }
}

TwinState state_of(const fat::DamageAccumulator& acc) {
  TwinState s;
  s.layout = layout_of(acc);
  s.accumulator = std::make_unique<fat::AccumulatorState>(acc.state());
  return s;
}

// Save through the store and load back (what a restart does).
TwinState through_store(const TwinState& s, const std::string& name) {
  StateStore store(fresh_twin_dir(name), "twin-state");
  std::string error;
  EXPECT_TRUE(store.save(encode_twin_state(s), 123, &error)) << error;
  StateStore again(store.copy_path(0).parent_path(), "twin-state");
  const StateLoad l = again.load();
  EXPECT_TRUE(l.record.has_value());
  auto d = decode_twin_state(*l.record, &error);
  EXPECT_TRUE(d.has_value()) << error;
  return d ? std::move(*d) : TwinState{};
}

std::uint64_t channel_ticks(const fat::AccumulatorState& s, std::size_t c, std::uint32_t bins) {
  return std::accumulate(s.bin_ticks[c].begin(), s.bin_ticks[c].begin() + bins + 1,
                         std::uint64_t{0});
}

TEST(TwinState, ARoundTripThroughTheStoreRestoresTheAccumulatorsBitForBit) {
  // Arrange
  const model::Drivetrain d = model::paper_2mw();
  const fat::ChannelSet cs(d, {});
  fat::AccumulatorConfig cfg;
  cfg.tick_s = 1.0 / 8000;
  fat::DamageAccumulator a(cs, cfg), b(cs, cfg);
  run(a, 3000, 1);
  // Act
  const TwinState loaded = through_store(state_of(a), "roundtrip");
  std::vector<RetiredChannel> retired;
  const CarryOver co = restore_accumulator(loaded, b, retired);
  // Assert
  EXPECT_TRUE(co.exact);
  EXPECT_EQ(std::memcmp(&a.state(), &b.state(), sizeof(fat::AccumulatorState)), 0);
  EXPECT_TRUE(retired.empty());
}

TEST(TwinState, AChangedRomRateCarriesEveryChannelsDamageAndTimeOver) {
  // Arrange: 8 kHz ticks, then the ROM runs at 25.6 kHz.
  const model::Drivetrain d = model::paper_2mw();
  const fat::ChannelSet cs(d, {});
  fat::AccumulatorConfig slow, fast;
  slow.tick_s = 1.0 / 8000;
  fast.tick_s = 1.0 / 25600;
  fat::DamageAccumulator before(cs, slow), after(cs, fast);
  run(before, 4000, 1);
  // Act
  std::vector<RetiredChannel> retired;
  const CarryOver co = restore_accumulator(through_store(state_of(before), "rate"), after, retired);
  // Assert: damage exactly, time to one new tick per channel, revolutions exactly.
  EXPECT_FALSE(co.exact);
  EXPECT_EQ(co.matched, cs.channel_count());
  EXPECT_EQ(co.added + co.retired, 0u);
  for (std::size_t c = 0; c < cs.channel_count(); ++c) {
    EXPECT_EQ(after.damage(c), before.damage(c)) << c;
    const double t_before = channel_ticks(before.state(), c, slow.bins) * slow.tick_s;
    const double t_after = channel_ticks(after.state(), c, fast.bins) * fast.tick_s;
    EXPECT_NEAR(t_after, t_before, fast.tick_s) << c;
    EXPECT_NEAR(after.histogram_damage(c), before.histogram_damage(c),
                1e-9 * before.histogram_damage(c))
        << c;
  }
  EXPECT_NEAR(after.elapsed_s(), before.elapsed_s(), fast.tick_s);
  EXPECT_EQ(after.state().rotor_rev_q, before.state().rotor_rev_q);
  // and it counts on from there
  const double d0 = after.damage(0);
  run(after, 100, 1);
  EXPECT_GT(after.damage(0), d0);
}

TEST(TwinState, OtherBinsAndFullScalesReBinTheHistogramKeepingItsTotalsAndDamage) {
  const model::Drivetrain d = model::paper_2mw();
  const fat::ChannelSet cs(d, {});
  fat::AccumulatorConfig a_cfg, b_cfg;
  a_cfg.tick_s = b_cfg.tick_s = 1e-3;
  b_cfg.bins = 128;
  for (std::size_t c = 0; c < cs.channel_count(); ++c)
    b_cfg.full_scale[c] = 0.8 * cs.channel(c).stress_full_scale;
  fat::DamageAccumulator a(cs, a_cfg), b(cs, b_cfg);
  run(a, 4000, 1);
  std::vector<RetiredChannel> retired;
  (void)restore_accumulator(through_store(state_of(a), "rebin"), b, retired);
  for (std::size_t c = 0; c < cs.channel_count(); ++c) {
    EXPECT_EQ(b.damage(c), a.damage(c));
    EXPECT_EQ(channel_ticks(b.state(), c, 128), channel_ticks(a.state(), c, a_cfg.bins));
    // The histogram's own damage (ISO 6336-6: at bin centres, the overflow at its largest
    // stress) re-binned: stresses beyond the new full scale count at the top of the saved bin
    // they came from (conservative); elsewhere within the centre error of the coarser bins.
    EXPECT_GE(b.histogram_damage(c), 0.95 * a.histogram_damage(c)) << c;
  }
}

TEST(TwinState, AChannelTheConfigurationLostIsRetiredAndTakenBackWhenItReturns) {
  // Arrange: paper-2mw, then the same without its last bearing, then paper-2mw again.
  const model::Drivetrain full = model::paper_2mw();
  model::Drivetrain fewer = full;
  const std::string lost = fewer.bearings.back().id;
  fewer.bearings.pop_back();
  const fat::ChannelSet cs_full(full, {}), cs_fewer(fewer, {});
  ASSERT_TRUE(cs_fewer.valid()) << cs_fewer.error();
  ASSERT_LT(cs_fewer.channel_count(), cs_full.channel_count());
  fat::AccumulatorConfig cfg;
  fat::DamageAccumulator a(cs_full, cfg), b(cs_fewer, cfg), c(cs_full, cfg);
  run(a, 3000, 1);
  // Act 1: restart with the bearing gone.
  std::vector<RetiredChannel> retired;
  const CarryOver co1 = restore_accumulator(through_store(state_of(a), "lost"), b, retired);
  // Assert 1: every remaining channel carried; the lost one retired with its damage.
  EXPECT_EQ(co1.matched, cs_fewer.channel_count());
  EXPECT_EQ(co1.retired, cs_full.channel_count() - cs_fewer.channel_count());
  ASSERT_FALSE(retired.empty());
  EXPECT_NE(retired.front().key.find(lost), std::string::npos);
  run(b, 500, 1, 1);
  // Act 2: the bearing is back (the retired list travels in the record).
  TwinState s2 = state_of(b);
  s2.retired = retired;
  std::vector<RetiredChannel> retired2;
  const CarryOver co2 = restore_accumulator(through_store(s2, "back"), c, retired2);
  // Assert 2: nothing retired any more, the bearing's lifetime damage back, others carried on.
  EXPECT_EQ(co2.returned, co1.retired);
  EXPECT_TRUE(retired2.empty());
  for (std::size_t k = 0; k < cs_full.channel_count(); ++k) {
    const std::string key = channel_key(cs_full.channel(k));
    EXPECT_GE(c.damage(k), a.damage(k)) << key;  // never backwards
    if (key.find(lost) != std::string::npos) {
      EXPECT_NEAR(c.damage(k), a.damage(k), 1e-15 * a.damage(k)) << key;
    }
  }
}

TEST(TwinState, TheRateHistoryAndCalibrationSurviveARestart) {
  const model::Drivetrain d = model::paper_2mw();
  const fat::ChannelSet cs(d, {});
  fat::DamageAccumulator a(cs, {});
  run(a, 100, 1);
  std::vector<fat::DamageRateHistory> h(cs.channel_count(), fat::DamageRateHistory(86400.0, 30));
  for (std::size_t c = 0; c < h.size(); ++c)
    for (int i = 0; i < 45; ++i) h[c].add_interval(1e-6 * (c + 1) * (1.0 + 0.1 * i));
  std::vector<double> boundary(cs.channel_count(), 0.5);
  TwinState s = state_of(a);
  s.rate = record_of(h, boundary);
  s.calibration = CalibrationRecord{7, "drivetwin-calibration 1", "rayleigh_eta 4.5\n"};
  const TwinState loaded = through_store(s, "rate-history");
  ASSERT_TRUE(loaded.rate && loaded.calibration);
  EXPECT_EQ(loaded.calibration->generation, 7u);
  EXPECT_EQ(loaded.calibration->text, "rayleigh_eta 4.5\n");
  std::vector<fat::DamageRateHistory> h2(cs.channel_count(), fat::DamageRateHistory(86400.0, 30));
  std::vector<double> b2(cs.channel_count(), 0.0);
  std::string note;
  ASSERT_TRUE(
      restore_rate_histories(*loaded.rate, loaded.layout.keys, layout_of(a).keys, h2, b2, &note));
  for (std::size_t c = 0; c < h.size(); ++c) {
    const fat::RulEstimate e1 = h[c].estimate(0.6), e2 = h2[c].estimate(0.6);
    EXPECT_EQ(e1.rul_s, e2.rul_s);
    EXPECT_EQ(e1.rul_low_s, e2.rul_low_s);
    EXPECT_EQ(e1.rul_short_term_s, e2.rul_short_term_s);
    EXPECT_EQ(b2[c], 0.5);
  }
  // another interval length: not used, said so
  std::vector<fat::DamageRateHistory> h3(cs.channel_count(), fat::DamageRateHistory(3600.0, 30));
  EXPECT_FALSE(
      restore_rate_histories(*loaded.rate, loaded.layout.keys, layout_of(a).keys, h3, b2, &note));
  EXPECT_NE(note.find("3600"), std::string::npos) << note;
}

TEST(TwinState, ADamagedSectionIsNamedWithWhatIsWrong) {
  const model::Drivetrain d = model::paper_2mw();
  const fat::ChannelSet cs(d, {});
  fat::DamageAccumulator a(cs, {});
  StateRecord rec;
  rec.sections = encode_twin_state(state_of(a));
  std::string error;
  // truncated accumulator section
  StateRecord cut = rec;
  for (auto& s : cut.sections)
    if (s.id == static_cast<std::uint32_t>(TwinSection::kAccumulator))
      s.bytes.resize(s.bytes.size() / 2);
  EXPECT_FALSE(decode_twin_state(cut, &error));
  EXPECT_NE(error.find("accumulator"), std::string::npos) << error;
  EXPECT_NE(error.find("truncated"), std::string::npos) << error;
  // a layout version from the future
  StateRecord future = rec;
  future.sections.front().version = 99;
  EXPECT_FALSE(decode_twin_state(future, &error));
  EXPECT_NE(error.find("layout version 99"), std::string::npos) << error;
  // no accumulator at all
  StateRecord none = rec;
  none.sections.erase(none.sections.begin() + 1);
  EXPECT_FALSE(decode_twin_state(none, &error));
  EXPECT_NE(error.find("no accumulator"), std::string::npos) << error;
}

}  // namespace
