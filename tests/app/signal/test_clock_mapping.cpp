// ClockMapping against a synthetic front end whose clock runs 80 ppm fast with an offset,
// its blocks delayed by a random one-sided latency (minimum + exponential queueing).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>

#include "signal/clock_mapping.hpp"

namespace {

using app::signal::ClockMapping;

struct SkewedFrontEnd {
  double drift = 80e-6;  // device runs fast: device = (1 + drift)·host + c
  std::int64_t host_at_device_zero = 5'000'000'000;  // [ns]
  std::int64_t min_latency_ns = 200'000;             // transfer + buffering floor
  double mean_queue_ns = 300'000.0;                  // exponential queueing on top
  // Host time at which device time d actually happened.
  std::int64_t host_of(std::int64_t device_ns) const {
    return host_at_device_zero +
           static_cast<std::int64_t>(std::llround(static_cast<double>(device_ns) / (1.0 + drift)));
  }
};

TEST(ClockMapping, RecoversDriftAndOffsetUpToTheMinimumLatency) {
  // Arrange: a CMS block every 1.09 ms of device time (914 frames/s) for 60 s.
  SkewedFrontEnd fe;
  std::mt19937_64 rng(7);
  std::exponential_distribution<double> queue(1.0 / fe.mean_queue_ns);
  app::signal::ClockMappingConfig cfg;
  cfg.min_latency_ns = fe.min_latency_ns;  // known here: then the mapping is absolute
  ClockMapping m(cfg);
  // Act
  for (std::int64_t d = 0; d < 60'000'000'000; d += 1'094'000) {
    const auto arrival = fe.host_of(d) + fe.min_latency_ns + static_cast<std::int64_t>(queue(rng));
    m.add(d, arrival);
  }
  // Assert: drift to 0.5 ppm (host = device/(1 + drift) → δ = −drift/(1 + drift)); a device
  // time maps to its true host time within 20 µs, a host time back within 20 µs.
  ASSERT_TRUE(m.valid());
  EXPECT_NEAR(m.drift_ppm(), -fe.drift / (1.0 + fe.drift) * 1e6, 0.5);
  for (std::int64_t d : {30'000'000'000LL, 59'000'000'000LL, 61'000'000'000LL}) {
    EXPECT_NEAR(static_cast<double>(m.to_host(d)), static_cast<double>(fe.host_of(d)), 20e3) << d;
    EXPECT_NEAR(static_cast<double>(m.to_device(fe.host_of(d))), static_cast<double>(d), 20e3) << d;
  }
}

TEST(ClockMapping, OrderTracksAWindowAgainstKeyphasorEdges) {
  // Arrange: a keyphasor edge every 70 ms of host time; the CMS window's samples are in device
  // time. Mapped into device time the edges must land where the window saw them: within a
  // small fraction of a 25.6 kHz sample period times a few.
  SkewedFrontEnd fe;
  std::mt19937_64 rng(11);
  std::exponential_distribution<double> queue(1.0 / fe.mean_queue_ns);
  app::signal::ClockMappingConfig cfg;
  cfg.min_latency_ns = fe.min_latency_ns;
  ClockMapping m(cfg);
  for (std::int64_t d = 0; d < 20'000'000'000; d += 1'094'000) {
    m.add(d, fe.host_of(d) + fe.min_latency_ns + static_cast<std::int64_t>(queue(rng)));
  }
  // Act / Assert: 50 edges; the true device time of each edge is known.
  for (int k = 0; k < 50; ++k) {
    const std::int64_t d_true = 19'000'000'000LL + k * 70'000'000LL;
    const std::int64_t edge_host = fe.host_of(d_true);
    EXPECT_NEAR(static_cast<double>(m.to_device(edge_host)), static_cast<double>(d_true), 20e3);
  }
}

TEST(ClockMapping, UnknownMinimumLatencyShiftsEveryTimeByTheSameConstant) {
  SkewedFrontEnd fe;
  std::mt19937_64 rng(3);
  std::exponential_distribution<double> queue(1.0 / fe.mean_queue_ns);
  ClockMapping m;  // min_latency_ns = 0: not known
  for (std::int64_t d = 0; d < 30'000'000'000; d += 1'094'000) {
    m.add(d, fe.host_of(d) + fe.min_latency_ns + static_cast<std::int64_t>(queue(rng)));
  }
  const double e1 = static_cast<double>(m.to_host(10'000'000'000) - fe.host_of(10'000'000'000));
  const double e2 = static_cast<double>(m.to_host(29'000'000'000) - fe.host_of(29'000'000'000));
  EXPECT_NEAR(e1, static_cast<double>(fe.min_latency_ns), 20e3);
  EXPECT_NEAR(e2 - e1, 0.0, 20e3);  // a constant: no speed error
}

TEST(ClockMapping, AFrontEndRestartStartsTheEstimateAfresh) {
  SkewedFrontEnd fe;
  ClockMapping m;
  for (std::int64_t d = 0; d < 10'000'000'000; d += 1'000'000) {
    m.add(d, fe.host_of(d) + fe.min_latency_ns);
  }
  ASSERT_TRUE(m.valid());
  // The device clock restarts at 0 while host time goes on.
  const std::int64_t host_restart = fe.host_of(10'000'000'000);
  for (std::int64_t d = 0; d < 5'000'000'000; d += 1'000'000) m.add(d, host_restart + d + 200'000);
  EXPECT_GE(m.resets(), 1u);
  ASSERT_TRUE(m.valid());
  EXPECT_NEAR(static_cast<double>(m.to_host(4'000'000'000)),
              static_cast<double>(host_restart + 4'000'000'000 + 200'000), 1e3);
}

}  // namespace
