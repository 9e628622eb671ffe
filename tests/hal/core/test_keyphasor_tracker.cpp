// Shaft speed from keyphasor edges: f = 1/(N·T), checked against edges placed
// at a known rate by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "hal/keyphasor.hpp"

namespace {

using namespace std::chrono_literals;

hal::KeyphasorEdge edge(std::chrono::nanoseconds t, std::uint32_t seq, bool rising = true) {
  return hal::KeyphasorEdge{t, rising, seq};
}

TEST(KeyphasorTracker, MeasuresTheHssSpeedOfThePaperPointFromOncePerRevEdges) {
  // Arrange: hss at 14.3032 Hz (rotor 8.33 rpm, drivetrain-2mw.md): T = 69.9145 ms
  hal::KeyphasorTracker t;
  const auto period = std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / 14.3032));

  // Act
  for (std::uint32_t k = 0; k < 5; ++k) t.on_edge(edge(period * k, k));
  const auto s = t.state(period * 4 + 10ms);

  // Assert
  ASSERT_TRUE(s.valid);
  EXPECT_NEAR(s.speed_hz, 14.3032, 1e-6);
  EXPECT_EQ(s.edges, 5u);
}

TEST(KeyphasorTracker, DividesByPulsesPerRevAndIgnoresFallingEdges) {
  // Arrange: 4 marks per revolution, 10 ms apart → 25 Hz
  hal::KeyphasorTracker::Config c;
  c.pulses_per_rev = 4;
  hal::KeyphasorTracker t(c);

  // Act
  std::uint32_t seq = 0;
  for (int k = 0; k < 4; ++k) {
    t.on_edge(edge(10ms * k, seq++, true));
    t.on_edge(edge(10ms * k + 1ms, seq++, false));
  }

  // Assert
  EXPECT_NEAR(t.state(31ms).speed_hz, 25.0, 1e-9);
}

TEST(KeyphasorTracker, DeclaresAStuckKeyphasorInvalidAfterTwoMissingRevolutions) {
  // Arrange: 10 Hz, then the pulses stop
  hal::KeyphasorTracker t;
  for (std::uint32_t k = 0; k < 3; ++k) t.on_edge(edge(100ms * k, k));

  // Act / Assert
  EXPECT_TRUE(t.state(250ms).valid);   // within 2 periods of the last edge (200 ms)
  EXPECT_FALSE(t.state(450ms).valid);  // 2.5 periods without an edge
}

TEST(KeyphasorTracker, RejectsBounceFasterThanTheMaximumSpeed) {
  // Arrange: 10 Hz with a bounce 100 µs after one edge (= 10 kHz > 200 Hz max)
  hal::KeyphasorTracker t;
  t.on_edge(edge(0ms, 0));
  t.on_edge(edge(100ms, 1));
  t.on_edge(edge(100ms + 100us, 2));
  t.on_edge(edge(200ms, 3));

  // Act
  const auto s = t.state(210ms);

  // Assert
  EXPECT_EQ(s.glitches, 1u);
  EXPECT_NEAR(s.speed_hz, 10.0, 1e-9);
}

TEST(KeyphasorTracker, DoesNotReportASpeedAcrossLostEdges) {
  // Arrange: sequence jumps from 1 to 3: one edge lost; the period 0.1→0.3 s spans two revolutions
  hal::KeyphasorTracker t;
  t.on_edge(edge(0ms, 0));
  t.on_edge(edge(100ms, 1));
  t.on_edge(edge(300ms, 3));
  const auto after_loss = t.state(310ms);
  t.on_edge(edge(400ms, 4));

  // Act
  const auto recovered = t.state(410ms);

  // Assert
  EXPECT_FALSE(after_loss.valid);
  EXPECT_EQ(after_loss.lost, 1u);
  ASSERT_TRUE(recovered.valid);
  EXPECT_NEAR(recovered.speed_hz, 10.0, 1e-9);
}

TEST(KeyphasorTracker, ExtrapolatesTheShaftAngleFromTheLastReference) {
  // Arrange: 10 Hz, last reference at 200 ms
  hal::KeyphasorTracker t;
  for (std::uint32_t k = 0; k < 3; ++k) t.on_edge(edge(100ms * k, k));

  // Act: a quarter revolution later
  const double a = t.angle_rad(225ms);

  // Assert
  EXPECT_NEAR(a, std::numbers::pi / 2.0, 1e-9);
}

}  // namespace
