// Online damage accumulator: ISO 6336-6 cycle counting, Palmgren–Miner additivity,
// exact bin time, bad-input handling, resumption, and no allocation per step.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <memory>
#include <new>

#include "model/fatigue/damage_accumulator.hpp"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

// noinline: once inlined, GCC pairs the free() with the new-expression and warns
// (-Wmismatched-new-delete) although the pair is this replacement's own malloc/free.
[[gnu::noinline]] void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
[[gnu::noinline]] void operator delete(void* p) noexcept { std::free(p); }
[[gnu::noinline]] void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace {
using namespace model::fatigue;

struct Fixture {
  model::Drivetrain drivetrain = model::paper_2mw();
  ChannelSet channels{drivetrain, ChannelOptions{}};
};

std::size_t channel_index(const ChannelSet& cs, const char* component, FailureMode mode) {
  for (std::size_t c = 0; c < cs.channel_count(); ++c) {
    if (cs.channel(c).component == component && cs.channel(c).mode == mode) return c;
  }
  return cs.channel_count();
}

TEST(Accumulator, CountsCyclesAsTimeTimesSpeedTimesContactsPerRevolution) {
  // Arrange: one hour at 14.8 rpm and rated torque, 100 ms steps with 1 ms ticks.
  Fixture f;
  AccumulatorConfig cfg;
  cfg.tick_s = 1e-3;
  DamageAccumulator acc(f.channels, cfg);
  const LoadSample loads = f.channels.quasi_static_loads(1.23e6);
  // Act
  int accumulated = 0;
  for (int i = 0; i < 36000; ++i)
    accumulated += acc.step(loads, 14.8, 100) == StepResult::kAccumulated;
  ASSERT_EQ(accumulated, 36000);
  // Assert: ISO 6336-6 n = t·n/60·contacts: rotor revs = 3600·14.8/60 = 888;
  // sun cycles = 888·3·99/21 = 12 557.71; D = n/N(σ) with σ the constant sun stress.
  // Revolutions are rounded to 2^-32 rev per step: at most 36000·2^-33 rev off.
  EXPECT_NEAR(acc.rotor_revolutions(), 888.0, 36000.0 * kRevQuantum / 2.0);
  const std::size_t sun = channel_index(f.channels, "sun", FailureMode::kContact);
  const double sigma = f.channels.stress(sun, 0, loads);
  const double n = 888.0 * 3.0 * 99.0 / 21.0;
  EXPECT_NEAR(acc.damage(sun), n / f.channels.channel(sun).curve.cycles_to_failure(sigma),
              1e-12 * acc.damage(sun));
}

TEST(Accumulator, EveryChannelsIncrementIsItsSnCurvesDamageAtItsStressOnBothSidesOfTheKnee) {
  // The step evaluates stresses per mesh and n/N(σ) from constants hoisted out of the
  // S-N curve; the oracle is the public per-source path: ChannelSet::stress() and
  // SnCurve::cycles_to_failure(). Loads from 5 % to 150 % of rated put every channel on
  // both sides of its knee; every knee branch.
  for (const KneeBranch branch :
       {KneeBranch::kHaibach, KneeBranch::kIsoLifeLine, KneeBranch::kNone}) {
    ChannelOptions options;
    options.branch = branch;
    options.lubrication.enabled = false;  // the S-N path alone (a_ISO: test_bearing_life.cpp)
    const model::Drivetrain d = model::paper_2mw();
    const ChannelSet cs(d, options);
    ASSERT_TRUE(cs.valid()) << cs.error();
    std::size_t below = 0, above = 0;
    for (const double torque : {0.06e6, 0.3e6, 0.9e6, 1.85e6}) {
      // Arrange: a load sample with every mesh and bearing at its own level.
      LoadSample loads = cs.quasi_static_loads(torque);
      for (std::size_t m = 0; m < cs.mesh_count(); ++m) loads.mesh_force_n[m] *= 1.0 + 0.03 * m;
      for (std::size_t b = 0; b < cs.bearing_count(); ++b)
        loads.bearing_axial_n[b] *= 1.0 + 0.5 * b;
      AccumulatorConfig cfg;
      cfg.tick_s = 1e-3;
      DamageAccumulator acc(cs, cfg);
      // Act: one step of 100 ms at 12 rpm.
      ASSERT_EQ(acc.step(loads, 12.0, 100), StepResult::kAccumulated);
      // Assert
      const double revs = 12.0 / 60.0 * 0.1;
      for (std::size_t c = 0; c < cs.channel_count(); ++c) {
        const Channel& ch = cs.channel(c);
        double expected = 0.0;
        for (std::size_t k = 0; k < ch.source_count; ++k) {
          const double sigma = cs.stress(c, k, loads);
          if (sigma > 0.0)
            expected +=
                revs * ch.sources[k].cycles_per_rotor_rev / ch.curve.cycles_to_failure(sigma);
          (sigma >= ch.curve.knee_stress() ? above : below) += 1;
        }
        EXPECT_NEAR(acc.damage(c), expected, 1e-12 * expected)
            << ch.component << " " << failure_mode_name(ch.mode) << " at " << torque << " N·m";
      }
    }
    if (branch != KneeBranch::kNone) {
      EXPECT_GT(below, 0u);
      EXPECT_GT(above, 0u);
    }
  }
}

TEST(Accumulator, AMeshsFourStressesAtOnceAreItsStressFunctionsToTheLastBit) {
  const model::Drivetrain d = model::paper_2mw();
  const ChannelSet cs(d, ChannelOptions{});
  for (std::size_t m = 0; m < cs.mesh_count(); ++m) {
    const MeshRating& r = cs.mesh(m);
    for (const double ft : {0.0, 1.0, 3.0e3, 2.0e5, 1.1e6, -4.0e5}) {
      const MeshStresses s = r.stresses(ft);
      for (int g = 0; g < 2; ++g) {
        EXPECT_EQ(s.contact_mpa[g], r.contact_stress_mpa(ft, g)) << cs.mesh_id(m) << " " << ft;
        EXPECT_EQ(s.bending_mpa[g], r.bending_stress_mpa(ft, g)) << cs.mesh_id(m) << " " << ft;
      }
    }
  }
}

TEST(Accumulator, MinerDamageIsAdditiveAndIndependentOfTheOrderOfLoadBlocks) {
  Fixture f;
  const LoadSample low = f.channels.quasi_static_loads(0.6e6),
                   high = f.channels.quasi_static_loads(1.3e6);
  DamageAccumulator a(f.channels, {}), b(f.channels, {}), low_only(f.channels, {}),
      high_only(f.channels, {});
  for (int i = 0; i < 1000; ++i) a.step(low, 10.0, 100);
  for (int i = 0; i < 500; ++i) a.step(high, 14.8, 100);
  for (int i = 0; i < 500; ++i) b.step(high, 14.8, 100);
  for (int i = 0; i < 1000; ++i) b.step(low, 10.0, 100);
  for (int i = 0; i < 1000; ++i) low_only.step(low, 10.0, 100);
  for (int i = 0; i < 500; ++i) high_only.step(high, 14.8, 100);
  for (std::size_t c = 0; c < f.channels.channel_count(); ++c) {
    const double sum = low_only.damage(c) + high_only.damage(c);
    EXPECT_NEAR(a.damage(c), sum, 1e-12 * sum) << f.channels.channel(c).component;
    EXPECT_NEAR(b.damage(c), sum, 1e-12 * sum) << f.channels.channel(c).component;
  }
}

TEST(Accumulator, BinTimeIsConservedExactlyBecauseTicksAreIntegers) {
  // Arrange: a state as after 1e9 steps of 10 ticks (1e10 ticks per source), spread over bins.
  Fixture f;
  DamageAccumulator acc(f.channels, {});
  AccumulatorState s = acc.state();
  const std::uint64_t steps = 1'000'000'000ull, dt = 10;
  s.elapsed_ticks = steps * dt;
  for (std::size_t c = 0; c < s.channel_count; ++c) {
    const std::uint64_t per_source = steps * dt;
    const std::uint64_t total = per_source * f.channels.channel(c).source_count;
    s.bin_ticks[c][3] = total / 3;
    s.bin_ticks[c][7] = total - total / 3;
  }
  ASSERT_TRUE(acc.restore(s));
  // Act: 1000 more steps of varying load and length.
  std::uint64_t added = 0;
  for (int i = 0; i < 1000; ++i) {
    const auto ticks = static_cast<std::uint32_t>(1 + (i * 7919) % 97);
    acc.step(f.channels.quasi_static_loads(1e4 * (i % 150)), 12.0, ticks);
    added += ticks;
  }
  // Assert: Σ bins == sources·(1e10 + added) to the tick (a running double sum of seconds
  // would round every addition: its ulp at 1e7 s is 1.9e-9 s).
  for (std::size_t c = 0; c < f.channels.channel_count(); ++c) {
    std::uint64_t sum = 0;
    for (std::uint32_t b = 0; b <= acc.state().bins; ++b) sum += acc.state().bin_ticks[c][b];
    EXPECT_EQ(sum, (steps * dt + added) * f.channels.channel(c).source_count);
  }
  EXPECT_EQ(acc.state().elapsed_ticks, steps * dt + added);
}

TEST(Accumulator, BadStepsAreCountedAndLeaveDamageAndHistogramUntouched) {
  Fixture f;
  DamageAccumulator acc(f.channels, {});
  acc.step(f.channels.quasi_static_loads(1e6), 12.0, 100);
  const AccumulatorState before = acc.state();
  LoadSample nan_load = f.channels.quasi_static_loads(1e6);
  nan_load.mesh_force_n[2] = std::nan("");
  LoadSample inf_bearing = f.channels.quasi_static_loads(1e6);
  inf_bearing.bearing_radial_n[4] = std::numeric_limits<double>::infinity();
  EXPECT_EQ(acc.step(nan_load, 12.0, 100), StepResult::kBadLoad);
  EXPECT_EQ(acc.step(inf_bearing, 12.0, 100), StepResult::kBadLoad);
  EXPECT_EQ(acc.step(f.channels.quasi_static_loads(1e6), -3.0, 100), StepResult::kBadSpeed);
  EXPECT_EQ(acc.step(f.channels.quasi_static_loads(1e6), std::nan(""), 100), StepResult::kBadSpeed);
  EXPECT_EQ(acc.step(f.channels.quasi_static_loads(1e6), 12.0, 0), StepResult::kZeroDt);
  EXPECT_EQ(acc.state().bad_load_steps, 2u);
  EXPECT_EQ(acc.state().bad_speed_steps, 2u);
  EXPECT_EQ(acc.state().zero_dt_steps, 1u);
  EXPECT_EQ(acc.state().elapsed_ticks, before.elapsed_ticks);
  for (std::size_t c = 0; c < f.channels.channel_count(); ++c) {
    EXPECT_EQ(acc.damage(c), before.damage[c] + before.damage_comp[c]);
    EXPECT_EQ(acc.state().bin_ticks[c], before.bin_ticks[c]);
  }
}

TEST(Accumulator, ResumesFromAPersistedStateAsIfNeverStopped) {
  Fixture f;
  DamageAccumulator straight(f.channels, {}), first(f.channels, {}), second(f.channels, {});
  for (int i = 0; i < 200; ++i) {
    const LoadSample l = f.channels.quasi_static_loads(7e3 * i);
    straight.step(l, 13.0, 50);
    (i < 120 ? first : second).step(l, 13.0, 50);
    if (i == 119) {
      auto copy = std::make_unique<AccumulatorState>(first.state());  // what the app persists
      ASSERT_TRUE(second.restore(*copy));
    }
  }
  for (std::size_t c = 0; c < f.channels.channel_count(); ++c) {
    EXPECT_EQ(second.damage(c), straight.damage(c));
    EXPECT_EQ(second.state().bin_rev_q[c], straight.state().bin_rev_q[c]);
  }
}

TEST(Accumulator, RefusesAStateWrittenWithADifferentBinConfiguration) {
  Fixture f;
  AccumulatorConfig other;
  other.bins = 100;
  DamageAccumulator a(f.channels, {}), b(f.channels, other);
  a.step(f.channels.quasi_static_loads(1e6), 12.0, 100);
  EXPECT_FALSE(b.restore(a.state()));
  EXPECT_EQ(b.state().valid_steps, 0u);
}

TEST(Accumulator, HistogramDamageAgreesWithTheExactSumWithinTheBinningError) {
  // Bins of full_scale/200; damage at the bin centre differs from the exact stress by at
  // most half a bin: |Δσ/σ| ≤ w/(2σ), so |ΔD/D| ≲ m'·w/(2σ) with m' = 2m − 1 = 33.07.
  Fixture f;
  DamageAccumulator acc(f.channels, {});
  for (int i = 0; i < 2000; ++i)
    acc.step(f.channels.quasi_static_loads(8e5 + 200.0 * i), 14.0, 100);
  const std::size_t sun = channel_index(f.channels, "sun", FailureMode::kContact);
  const double sigma = f.channels.stress(sun, 0, f.channels.quasi_static_loads(1e6));
  const double bound = 33.07 * acc.bin_width(sun) / (2.0 * sigma);
  EXPECT_NEAR(acc.histogram_damage(sun) / acc.damage(sun), 1.0, bound);
}

TEST(Accumulator, StepDoesNotAllocate) {
  Fixture f;
  DamageAccumulator acc(f.channels, {});
  const LoadSample l = f.channels.quasi_static_loads(1e6);
  const long before = g_allocations.load();
  for (int i = 0; i < 10000; ++i) acc.step(l, 12.0, 10);
  EXPECT_EQ(g_allocations.load(), before);
}

}  // namespace
