// Simulation backends: every injected fault shows up as a status (or counter),
// clears without re-configuring, and no call waits for data. Deterministic:
// driven by a ManualClock.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "../no_alloc.hpp"
#include "hal/memory_backends.hpp"
#include "hal/sim_backends.hpp"

namespace {

using namespace std::chrono_literals;
using hal::SimFault;
using hal::Status;

// ---- SCADA ----

struct ScadaFixture {
  hal::ManualClock clock;
  hal::SimScadaSource src{hal::sim_scada_paper_point(), clock};
  ScadaFixture() {
    EXPECT_EQ(src.configure(), Status::kOk);
    EXPECT_EQ(src.activate(), Status::kOk);
  }
  Status step(std::chrono::milliseconds dt, hal::ScadaData& d) {
    clock.advance(dt);
    return src.read(clock.now(), d);
  }
};

TEST(SimScadaSource, DeliversThePaperPointWithinItsVariation) {
  // Arrange
  ScadaFixture f;
  hal::ScadaData d;

  // Act
  const Status s = f.src.read(f.clock.now(), d);

  // Assert: ±2 % around drivetrain-2mw.md's check point
  EXPECT_EQ(s, Status::kOk);
  EXPECT_NEAR(d[hal::ScadaQuantity::kWindSpeed].value, 6.75, 0.02 * 6.75);
  EXPECT_NEAR(d[hal::ScadaQuantity::kRotorTorque].value, 361747.0, 0.02 * 361747.0);
  EXPECT_FALSE(d[hal::ScadaQuantity::kYawError].valid);
}

TEST(SimScadaSource, ASilentControllerGoesStaleAndRecoversWhenItAnswersAgain) {
  // Arrange: updates every 1 s, stale after 3 s
  ScadaFixture f;
  hal::ScadaData d;
  ASSERT_EQ(f.step(0ms, d), Status::kOk);

  // Act
  f.src.inject(SimFault::kSilent);
  Status during = Status::kOk;
  for (int i = 0; i < 5; ++i) during = f.step(1000ms, d);
  const std::uint32_t errors = d.error_count;
  f.src.inject(SimFault::kNone);
  const Status after = f.step(1000ms, d);

  // Assert
  EXPECT_EQ(during, Status::kStale);
  EXPECT_GE(errors, 5u);
  EXPECT_EQ(after, Status::kOk);
}

TEST(SimScadaSource, StuckRegistersFreezeTheSnapshotAndGoStale) {
  // Arrange
  ScadaFixture f;
  hal::ScadaData before, d;
  ASSERT_EQ(f.step(0ms, before), Status::kOk);

  // Act
  f.src.inject(SimFault::kStuck);
  Status s = Status::kOk;
  for (int i = 0; i < 4; ++i) s = f.step(1000ms, d);

  // Assert: same values and time stamp as before the fault
  EXPECT_EQ(s, Status::kStale);
  EXPECT_EQ(d[hal::ScadaQuantity::kWindSpeed].value, before[hal::ScadaQuantity::kWindSpeed].value);
  EXPECT_EQ(d.last_update, before.last_update);
}

TEST(SimScadaSource, GarbageIsAProtocolErrorWithInvalidValuesUntilCleared) {
  // Arrange
  ScadaFixture f;
  hal::ScadaData d;
  ASSERT_EQ(f.step(0ms, d), Status::kOk);

  // Act
  f.src.inject(SimFault::kGarbage);
  const Status bad = f.step(1000ms, d);
  const bool wind_valid_during = d[hal::ScadaQuantity::kWindSpeed].valid;
  f.src.inject(SimFault::kNone);
  const Status good = f.step(1000ms, d);

  // Assert
  EXPECT_EQ(bad, Status::kProtocolError);
  EXPECT_FALSE(wind_valid_during);
  EXPECT_EQ(good, Status::kOk);
  EXPECT_TRUE(d[hal::ScadaQuantity::kWindSpeed].valid);
}

TEST(SimScadaSource, NoisyDataStaysValidButSpreadsFarWider) {
  // Arrange
  ScadaFixture f;
  f.src.inject(SimFault::kNoisy);
  hal::ScadaData d;
  double max_dev = 0.0;

  // Act
  for (int i = 0; i < 50; ++i) {
    EXPECT_EQ(f.step(1000ms, d), Status::kOk);
    max_dev = std::max(max_dev, std::fabs(d[hal::ScadaQuantity::kWindSpeed].value / 6.75 - 1.0));
  }

  // Assert: beyond the ±2 % of normal operation
  EXPECT_GT(max_dev, 0.1);
}

// ---- CMS ----

struct CmsFixture {
  hal::ManualClock clock;
  hal::SimCmsConfig cfg;
  std::unique_ptr<hal::SimCmsStream> cms;
  explicit CmsFixture(std::uint8_t channels = 1) {
    cfg.channels = channels;
    cms = std::make_unique<hal::SimCmsStream>(cfg, clock);
    EXPECT_EQ(cms->configure(), Status::kOk);
    EXPECT_EQ(cms->activate(), Status::kOk);
  }
  /// Advances by dt in steps of at most 10 ms (a loop reading at 100 Hz),
  /// draining after each; returns the blocks read.
  std::vector<hal::CmsBlock> run(std::chrono::microseconds dt) {
    std::vector<hal::CmsBlock> v;
    while (dt.count() > 0) {
      const auto step = std::min(dt, std::chrono::microseconds(10000));
      clock.advance(step);
      dt -= step;
      hal::CmsBlock b;
      while (cms->read(b) == Status::kOk) v.push_back(b);
    }
    return v;
  }
};

// 28 samples at 25.6 kHz: a frame every 1093.75 µs.
constexpr auto kTenFrames = std::chrono::microseconds(10938);

TEST(SimCmsStream, DeliversTheToneThroughTheCanDecoderInOrder) {
  // Arrange
  CmsFixture f;

  // Act: 10 frame periods after the first frame at t = 0
  const auto blocks = f.run(kTenFrames);

  // Assert: 11 frames (t0 = 0 … 10·1093.75 µs); the samples follow
  // 2 sin(2π·371.884 t) within quantisation (0.001) and noise (0.05)
  ASSERT_EQ(blocks.size(), 11u);
  for (std::size_t k = 0; k < blocks.size(); ++k) EXPECT_EQ(blocks[k].sequence, k);
  const auto& b = blocks[3];
  const double t0 = std::chrono::duration<double>(b.stamp).count();
  for (std::size_t i = 0; i < b.count; ++i) {
    const double t = t0 + static_cast<double>(i) / 25600.0;
    EXPECT_NEAR(b.samples[i], 2.0 * std::sin(2.0 * M_PI * 371.884 * t), 0.052);
  }
  EXPECT_EQ(f.cms->health(f.clock.now()), Status::kOk);
}

TEST(SimCmsStream, GapsAreCountedAndReportedThenClear) {
  // Arrange
  CmsFixture f;
  (void)f.run(kTenFrames);

  // Act: 40 frames with every 4th lost
  f.cms->inject(SimFault::kGaps);
  (void)f.run(4 * kTenFrames);
  const Status during = f.cms->health(f.clock.now());
  const auto st = f.cms->stats();
  f.cms->inject(SimFault::kNone);
  (void)f.run(std::chrono::microseconds(600000));  // beyond error_hold (500 ms)

  // Assert
  EXPECT_EQ(during, Status::kGap);
  EXPECT_GE(st.gaps, 9u);
  EXPECT_EQ(st.lost_blocks, st.gaps);  // one frame lost per gap
  EXPECT_EQ(f.cms->health(f.clock.now()), Status::kOk);
}

TEST(SimCmsStream, GarbageFramesAreDroppedAsMalformedAndDecodingResumes) {
  // Arrange
  CmsFixture f;
  (void)f.run(kTenFrames);

  // Act
  f.cms->inject(SimFault::kGarbage);
  const auto during = f.run(kTenFrames);
  const Status health_during = f.cms->health(f.clock.now());
  f.cms->inject(SimFault::kNone);
  (void)f.run(std::chrono::microseconds(600000));
  const auto after = f.run(kTenFrames);

  // Assert
  EXPECT_GE(f.cms->stats().malformed, 9u);
  EXPECT_LE(during.size(), 1u);  // random bytes almost never form a valid frame
  EXPECT_EQ(health_during, Status::kProtocolError);
  EXPECT_GE(after.size(), 9u);
  EXPECT_EQ(f.cms->health(f.clock.now()), Status::kOk);
}

TEST(SimCmsStream, AStuckFrontEndRepeatsItselfIsDroppedAsDuplicatesAndGoesStale) {
  // Arrange
  CmsFixture f;
  (void)f.run(kTenFrames);

  // Act: 600 ms of the same sequence number
  f.cms->inject(SimFault::kStuck);
  const auto during = f.run(std::chrono::microseconds(600000));
  const Status health = f.cms->health(f.clock.now());

  // Assert
  EXPECT_TRUE(during.empty());
  EXPECT_GT(f.cms->stats().duplicates, 100u);
  EXPECT_EQ(health, Status::kStale);
}

TEST(SimCmsStream, ReportsBusOffThenRecoversWhenTheControllerRestarts) {
  // Arrange
  CmsFixture f;
  (void)f.run(kTenFrames);

  // Act
  f.cms->inject(SimFault::kBusOff);
  f.clock.advance(kTenFrames);
  hal::CmsBlock b;
  const Status read_off = f.cms->read(b);
  const Status health_off = f.cms->health(f.clock.now());
  f.cms->inject(SimFault::kNone);
  const auto after = f.run(kTenFrames);

  // Assert
  EXPECT_EQ(read_off, Status::kBusOff);
  EXPECT_EQ(health_off, Status::kBusOff);
  EXPECT_FALSE(after.empty());
  EXPECT_EQ(f.cms->stats().bus_off, 1u);
  EXPECT_GE(f.cms->stats().recoveries, 1u);
}

TEST(SimCmsStream, ASilentBusGoesStaleAndAReaderNeverWaits) {
  // Arrange
  CmsFixture f;
  (void)f.run(kTenFrames);

  // Act
  f.cms->inject(SimFault::kSilent);
  f.clock.advance(std::chrono::microseconds(600000));
  hal::CmsBlock b;
  const Status s = f.cms->read(b);  // returns at once with no data

  // Assert
  EXPECT_EQ(s, Status::kNoData);
  EXPECT_EQ(f.cms->health(f.clock.now()), Status::kStale);
}

TEST(SimCmsStream, AStalledReaderSeesTheLostFramesAsAGap) {
  // Arrange
  CmsFixture f;
  (void)f.run(kTenFrames);

  // Act: 1 s without reading = 914 frames, more than the per-read bound allows
  f.clock.advance(1s);
  const auto blocks = f.run(std::chrono::microseconds(10000));

  // Assert
  EXPECT_GE(f.cms->stats().gaps, 1u);
  EXPECT_GT(f.cms->stats().lost_blocks, 500u);
  EXPECT_FALSE(blocks.empty());
}

// ---- keyphasor ----

TEST(SimKeyphasor, StuckProducesNoEdgesAndTheTrackerInvalidatesThenRecovers) {
  // Arrange: hss at 14.3032 Hz
  hal::ManualClock clock;
  hal::SimKeyphasor kp(hal::SimKeyphasorConfig{}, clock);
  ASSERT_EQ(kp.configure(), Status::kOk);
  ASSERT_EQ(kp.activate(), Status::kOk);
  hal::KeyphasorTracker tracker;
  auto drain = [&] {
    hal::KeyphasorEdge e;
    while (kp.read(e) == Status::kOk) tracker.on_edge(e);
  };
  clock.advance(1s);
  drain();
  const auto healthy = tracker.state(clock.now());

  // Act
  kp.inject(SimFault::kStuck);
  clock.advance(1s);
  drain();
  const auto stuck = tracker.state(clock.now());
  kp.inject(SimFault::kNone);
  clock.advance(1s);
  drain();
  const auto recovered = tracker.state(clock.now());

  // Assert
  ASSERT_TRUE(healthy.valid);
  EXPECT_NEAR(healthy.speed_hz, 14.3032, 1e-6);
  EXPECT_FALSE(stuck.valid);
  ASSERT_TRUE(recovered.valid);
  EXPECT_NEAR(recovered.speed_hz, 14.3032, 1e-6);
}

TEST(SimKeyphasor, LostEdgesShowAsSequenceJumps) {
  // Arrange
  hal::ManualClock clock;
  hal::SimKeyphasor kp(hal::SimKeyphasorConfig{}, clock);
  ASSERT_EQ(kp.configure(), Status::kOk);
  ASSERT_EQ(kp.activate(), Status::kOk);
  kp.inject(SimFault::kGaps);
  hal::KeyphasorTracker tracker;

  // Act: 2 s = 29 edges, every 4th lost
  clock.advance(2s);
  hal::KeyphasorEdge e;
  while (kp.read(e) == Status::kOk) tracker.on_edge(e);

  // Assert
  EXPECT_GE(tracker.state(clock.now()).lost, 6u);
}

// ---- outputs ----

TEST(MemoryDigitalOutputs, FallsToTheSafeStatesOnDeactivate) {
  // Arrange
  hal::MemoryDigitalOutputs out;
  ASSERT_EQ(out.configure(), Status::kOk);
  EXPECT_TRUE(out.alarm_raised());  // configured into the safe state
  ASSERT_EQ(out.activate(), Status::kOk);
  ASSERT_EQ(out.set_alarm(false), Status::kOk);
  ASSERT_EQ(out.set_watchdog(true), Status::kOk);

  // Act
  ASSERT_EQ(out.deactivate(), Status::kOk);

  // Assert
  EXPECT_FALSE(out.watchdog());
  EXPECT_TRUE(out.alarm_raised());
  EXPECT_EQ(out.set_watchdog(true), Status::kWrongState);
}

TEST(NoAllocScope, CountsAnAllocationOnThisThread) {
  // The helper itself: a zero below must mean "nothing allocated", not "not counted".
  no_alloc::Scope scope;
  auto* v = new std::vector<int>(100);
  delete v;
  EXPECT_EQ(scope.allocations(), 2u);  // the vector object and its buffer
}

TEST(SimBackends, ReadPathsAllocateNothingOnceActive) {
  // Arrange: everything configured and activated (allocation allowed up to here)
  hal::ManualClock clock;
  hal::SimScadaSource scada(hal::sim_scada_paper_point(), clock);
  hal::SimCmsStream cms(hal::SimCmsConfig{}, clock);
  hal::SimKeyphasor kp(hal::SimKeyphasorConfig{}, clock);
  hal::MemoryDigitalOutputs out;
  hal::KeyphasorTracker tracker;
  for (hal::Device* d : std::initializer_list<hal::Device*>{&scada, &cms, &kp, &out}) {
    ASSERT_EQ(d->configure(), Status::kOk);
    ASSERT_EQ(d->activate(), Status::kOk);
  }
  hal::ScadaData sd;
  hal::CmsBlock b;
  hal::KeyphasorEdge e;

  // Act: 2 s of a 100 Hz loop, with a fault switched on and off on the way
  no_alloc::Scope scope;
  for (int k = 0; k < 200; ++k) {
    clock.advance(10ms);
    if (k == 50) cms.inject(SimFault::kGarbage);
    if (k == 100) cms.inject(SimFault::kNone);
    (void)scada.read(clock.now(), sd);
    while (cms.read(b) == Status::kOk) {
    }
    (void)cms.health(clock.now());
    while (kp.read(e) == Status::kOk) tracker.on_edge(e);
    (void)tracker.state(clock.now());
    (void)out.set_watchdog((k & 1) != 0);
  }

  // Assert
  EXPECT_EQ(scope.allocations(), 0u);
  EXPECT_GT(cms.stats().blocks, 1000u);  // the loop did real work
}

}  // namespace
