// The application's mailboxes (app/loop/mailbox.hpp): a rebuilt model handed to the RT
// thread and the replaced one handed back without loss or double ownership, a
// calibration result read on another thread never torn, the bounded queue's limits.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <thread>

#include "loop/mailbox.hpp"
#include "model/calibration/calibrator.hpp"

namespace {

using app::loop::Handover;
using app::loop::Latest;
using app::loop::Queue;

std::atomic<int> g_alive{0};
struct Model {
  explicit Model(int id_) : id(id_) { g_alive.fetch_add(1); }
  ~Model() { g_alive.fetch_sub(1); }
  int id;
};

TEST(Handover, ASecondOfferBeforeTheTakeReturnsTheFirstInsteadOfLosingIt) {
  // Arrange
  g_alive = 0;
  Handover<Model> box;
  // Act
  EXPECT_EQ(box.offer(std::make_unique<Model>(1)), nullptr);
  const std::unique_ptr<Model> back = box.offer(std::make_unique<Model>(2));
  Model* taken = box.take();
  // Assert: the RT side gets the newest; the builder got the untaken one back.
  ASSERT_NE(back, nullptr);
  EXPECT_EQ(back->id, 1);
  ASSERT_NE(taken, nullptr);
  EXPECT_EQ(taken->id, 2);
  EXPECT_EQ(box.take(), nullptr);
  EXPECT_FALSE(box.pending());
  EXPECT_TRUE(box.give_back(taken));
  EXPECT_EQ(box.reclaim()->id, 2);
  EXPECT_EQ(box.reclaim(), nullptr);
}

TEST(Handover, AFullReturnPathRefusesAndTheDestructorFreesWhatItHolds) {
  g_alive = 0;
  {
    Handover<Model, 2> box;
    Model a(0), b(0);  // stand-ins never freed by the box
    std::unique_ptr<Model> r1 = std::make_unique<Model>(1), r2 = std::make_unique<Model>(2);
    EXPECT_TRUE(box.give_back(r1.release()));
    EXPECT_TRUE(box.give_back(r2.release()));
    Model* extra = new Model(3);
    EXPECT_FALSE(box.give_back(extra));  // full: the caller keeps it
    delete extra;
    EXPECT_EQ(box.offer(std::make_unique<Model>(4)), nullptr);
    EXPECT_EQ(g_alive.load(), 2 + 3);  // a, b, 1, 2, 4
  }
  EXPECT_EQ(g_alive.load(), 0);  // 1, 2 (returned) and 4 (offered) freed by the box
}

TEST(Handover, ObjectsCrossingBetweenTwoThreadsAreNeverLostOrFreedTwice) {
  // Arrange: a builder offers 2000 models and frees what comes back; the "RT" side
  // adopts whatever is offered and gives back the one it replaces.
  g_alive = 0;
  constexpr int kModels = 2000;
  std::atomic<bool> done{false};
  int adopted = 0, order_errors = 0;
  {
    Handover<Model> box;
    std::thread rt([&] {
      Model* active = nullptr;
      Model* keep = nullptr;  // a replaced model the full return path refused
      int last = 0;
      while (!done.load() || box.pending()) {
        if (keep && box.give_back(keep)) keep = nullptr;
        if (keep) continue;
        if (Model* next = box.take()) {
          ++adopted;
          if (next->id <= last) ++order_errors;
          last = next->id;
          if (!box.give_back(active)) keep = active;
          active = next;
        }
      }
      while (keep && !box.give_back(keep)) {
      }
      if (!box.give_back(active)) delete active;  // test shutdown only
    });
    // Act
    for (int i = 1; i <= kModels; ++i) {
      box.offer(std::make_unique<Model>(i));  // an untaken earlier offer is freed here
      while (box.reclaim()) {
      }
    }
    done.store(true);
    rt.join();
    while (box.reclaim()) {
    }
  }
  // Assert
  EXPECT_EQ(g_alive.load(), 0);
  EXPECT_GT(adopted, 0);
  EXPECT_EQ(order_errors, 0);
}

TEST(Latest, ACalibrationResultReadOnAnotherThreadIsNeverTorn) {
  // Arrange: the calibration thread publishes results whose fields all derive from the
  // generation; a mix of two publications breaks the identity the reader checks.
  Latest<model::calibration::CalibrationResult> box;
  std::atomic<bool> done{false};
  std::atomic<int> torn{0}, reads{0};
  std::thread reader([&] {
    std::uint32_t last = 0;
    while (!done.load()) {
      model::calibration::CalibrationResult r;
      if (!box.read(r)) continue;
      reads.fetch_add(1);
      const double g = r.generation;
      if (r.evaluations != 8u * r.generation || r.parameters.rayleigh_eta != g ||
          r.indicators[1].f3 != -g || r.generation < last)
        torn.fetch_add(1);
      last = r.generation;
    }
  });
  // Act
  for (std::uint32_t g = 1; g <= 20000; ++g) {
    model::calibration::CalibrationResult r;
    r.generation = g;
    r.evaluations = 8u * g;
    r.parameters.rayleigh_eta = g;
    r.indicators[1].f3 = -static_cast<double>(g);
    box.write(r);
  }
  done.store(true);
  reader.join();
  // Assert
  model::calibration::CalibrationResult last;
  ASSERT_TRUE(box.read(last));
  EXPECT_EQ(last.generation, 20000u);
  EXPECT_EQ(torn.load(), 0);
}

TEST(Queue, PushFailsWhenFullAndPopWhenEmptyInFifoOrder) {
  Queue<int, 3> q;
  int out = 0;
  EXPECT_FALSE(q.pop(out));
  EXPECT_TRUE(q.push(1));
  EXPECT_TRUE(q.push(2));
  EXPECT_TRUE(q.push(3));
  EXPECT_FALSE(q.push(4));
  EXPECT_EQ(q.size(), 3u);
  ASSERT_TRUE(q.pop(out));
  EXPECT_EQ(out, 1);
  ASSERT_TRUE(q.pop(out));
  EXPECT_EQ(out, 2);
}

}  // namespace
