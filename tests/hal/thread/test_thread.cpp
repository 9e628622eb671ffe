// hal::Thread: every attribute is checked from inside the started thread with the OS's
// own queries (pthread_getname_np, pthread_getattr_np, sched_getscheduler, getpriority,
// sched_getaffinity), independently of the report the class gives.
#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <string>

#include "hal/thread.hpp"

namespace {

struct Seen {
  std::string name;
  std::size_t stack_bytes = 0;
  int policy = -1;
  int nice = 100;
  int cpus = 0;  // CPUs in the affinity mask
  bool cpu0 = false;
};

Seen observe() {
  Seen s;
  char name[32] = {};
  pthread_getname_np(pthread_self(), name, sizeof name);
  s.name = name;
  pthread_attr_t attr;
  if (pthread_getattr_np(pthread_self(), &attr) == 0) {
    pthread_attr_getstacksize(&attr, &s.stack_bytes);
    pthread_attr_destroy(&attr);
  }
  s.policy = sched_getscheduler(0);
  errno = 0;
  s.nice = getpriority(PRIO_PROCESS, static_cast<id_t>(gettid()));
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) == 0) {
    s.cpus = CPU_COUNT(&set);
    s.cpu0 = CPU_ISSET(0, &set);
  }
  return s;
}

Seen run(const hal::ThreadAttributes& a, hal::ThreadReport* report = nullptr) {
  Seen seen;
  hal::Thread t;
  EXPECT_EQ(t.start(a, [&seen] { seen = observe(); }), hal::Status::kOk);
  t.join();
  if (report) *report = t.report();
  return seen;
}

TEST(Thread, NameStackAndNiceAreWhatWasAsked) {
  // Arrange: a background thread at nice 5 with a 256 KiB stack.
  const hal::ThreadAttributes a{"dt-test-batch", hal::SchedPolicy::kBatch, 5, -1, 256 * 1024};
  // Act
  hal::ThreadReport r;
  const Seen s = run(a, &r);
  // Assert: raising the nice value needs no privilege, so everything is granted.
  EXPECT_EQ(s.name, "dt-test-batch");
  // At least what was asked (sanitizers enlarge stacks), and what the report says.
  EXPECT_GE(s.stack_bytes, 256u * 1024u);
  EXPECT_EQ(s.stack_bytes, r.stack_bytes);
  EXPECT_EQ(s.policy, SCHED_BATCH);
  EXPECT_EQ(s.nice, 5);
  EXPECT_TRUE(r.policy_applied);
  EXPECT_TRUE(r.warning.empty()) << r.warning;
}

TEST(Thread, LongNamesAreCutToFifteenCharacters) {
  const Seen s = run({"drivetwin-calibration", hal::SchedPolicy::kOther, 0, -1, 0});
  EXPECT_EQ(s.name, "drivetwin-calib");
}

TEST(Thread, IdlePolicyIsApplied) {
  const Seen s = run({"dt-idle", hal::SchedPolicy::kIdle, 0, -1, 0});
  EXPECT_EQ(s.policy, SCHED_IDLE);
}

TEST(Thread, PinnedThreadRunsOnItsCpuOnly) {
  hal::ThreadReport r;
  const Seen s = run({"dt-pinned", hal::SchedPolicy::kOther, 0, 0, 0}, &r);
  EXPECT_TRUE(r.affinity_applied);
  EXPECT_EQ(s.cpus, 1);
  EXPECT_TRUE(s.cpu0);
}

TEST(Thread, ACpuThatDoesNotExistIsReportedAndTheThreadStillRuns) {
  // Arrange: CPU 1000 exists on no machine this runs on.
  std::atomic<bool> ran{false};
  hal::Thread t;
  // Act
  ASSERT_EQ(t.start({"dt-nocpu", hal::SchedPolicy::kOther, 0, 1000, 0}, [&] { ran = true; }),
            hal::Status::kOk);
  t.join();
  // Assert
  EXPECT_TRUE(ran);
  EXPECT_FALSE(t.report().affinity_applied);
  EXPECT_NE(t.report().affinity_errno, 0);
  EXPECT_NE(t.report().warning.find("CPU 1000"), std::string::npos) << t.report().warning;
}

TEST(Thread, RealTimePolicyIsGrantedOrRefusedWithAFallbackThatMatchesTheReport) {
  // Arrange: SCHED_FIFO needs CAP_SYS_NICE or an RLIMIT_RTPRIO; either outcome is legal,
  // but the report must say which one happened and the thread must run as reported.
  hal::ThreadReport r;
  // Act
  const Seen s = run({"dt-fifo", hal::SchedPolicy::kFifo, 10, -1, 0}, &r);
  // Assert
  if (r.policy_applied) {
    EXPECT_EQ(s.policy, SCHED_FIFO);
    EXPECT_TRUE(r.warning.empty());
  } else {
    EXPECT_EQ(s.policy, SCHED_OTHER);
    EXPECT_EQ(s.nice, 0);
    EXPECT_NE(r.warning.find("refused"), std::string::npos) << r.warning;
  }
}

TEST(Thread, StartsInAKnownStateWhateverTheCreatorRunsAt) {
  // Arrange: the creator itself at nice 3 (raising it is always permitted).
  hal::ThreadReport r;
  Seen s;
  hal::Thread outer;
  ASSERT_EQ(outer.start({"dt-creator", hal::SchedPolicy::kOther, 3, -1, 0},
                        [&] {
                          s = run({"dt-child", hal::SchedPolicy::kOther, 0, -1, 0}, &r);
                        }),
            hal::Status::kOk);
  outer.join();
  // Assert: the child runs at the nice value it asked for, not the creator's.
  EXPECT_EQ(s.policy, SCHED_OTHER);
  EXPECT_TRUE(s.nice == 0 || !r.policy_applied) << "nice " << s.nice;
}

TEST(Thread, InvalidAttributesAreRefusedByName) {
  EXPECT_NE(hal::validate({"x", hal::SchedPolicy::kFifo, 0, -1, 0}).find("priority"),
            std::string::npos);
  EXPECT_NE(hal::validate({"x", hal::SchedPolicy::kOther, 25, -1, 0}).find("nice"),
            std::string::npos);
  EXPECT_NE(hal::validate({"", hal::SchedPolicy::kOther, 0, -1, 0}).find("name"),
            std::string::npos);
  EXPECT_NE(hal::validate({"x", hal::SchedPolicy::kOther, 0, -2, 0}).find("cpu"),
            std::string::npos);
  EXPECT_NE(hal::validate({"x", hal::SchedPolicy::kOther, 0, -1, 100}).find("stack_bytes"),
            std::string::npos);
  EXPECT_TRUE(hal::validate({"x", hal::SchedPolicy::kRoundRobin, 99, 1, 65536}).empty());
  hal::Thread t;
  EXPECT_EQ(t.start({"x", hal::SchedPolicy::kFifo, 0, -1, 0}, [] {}), hal::Status::kInvalidConfig);
  EXPECT_FALSE(t.joinable());
}

TEST(Thread, ASecondStartWhileRunningIsAWrongState) {
  std::atomic<bool> go{false};
  hal::Thread t;
  ASSERT_EQ(t.start({"dt-a", hal::SchedPolicy::kOther, 0, -1, 0},
                    [&] {
                      while (!go) sched_yield();
                    }),
            hal::Status::kOk);
  EXPECT_EQ(t.start({"dt-b", hal::SchedPolicy::kOther, 0, -1, 0}, [] {}), hal::Status::kWrongState);
  go = true;
  t.join();
  EXPECT_FALSE(t.joinable());
}

}  // namespace
