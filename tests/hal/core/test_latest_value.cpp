// LatestValue (seqlock): a reader never sees a torn value while a writer
// publishes concurrently.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "hal/latest_value.hpp"

namespace {

struct Wide {
  std::uint64_t a, b, c, d, e;  // all equal in every written value
};

TEST(LatestValue, ReportsNothingBeforeTheFirstWrite) {
  hal::LatestValue<Wide> v;
  Wide out{};
  EXPECT_FALSE(v.read(out));
}

TEST(LatestValue, NeverReturnsATornValueUnderConcurrentWrites) {
  // Arrange
  hal::LatestValue<Wide> v;
  v.write(Wide{0, 0, 0, 0, 0});
  std::atomic<bool> stop{false};
  std::thread writer([&] {
    // Paced like a bus I/O thread (a write every few µs), not a tight loop that
    // would starve the bounded-retry reader by design.
    for (std::uint64_t k = 1; !stop.load(); ++k) {
      v.write(Wide{k, k, k, k, k});
      std::this_thread::sleep_for(std::chrono::microseconds(2));
    }
  });

  // Act
  int torn = 0, reads = 0;
  for (int i = 0; i < 200000; ++i) {
    Wide w{};
    if (v.read(w)) {
      ++reads;
      if (!(w.a == w.b && w.b == w.c && w.c == w.d && w.d == w.e)) ++torn;
    }
  }
  stop = true;
  writer.join();

  // Assert
  EXPECT_EQ(torn, 0);
  EXPECT_GT(reads, 0);
}

}  // namespace
