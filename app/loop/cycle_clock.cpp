#include "loop/cycle_clock.hpp"

#include <cerrno>
#include <ctime>

namespace app::loop {
namespace {

constexpr std::int64_t kNsPerS = 1'000'000'000;

void sleep_until(std::int64_t deadline_ns) {
  timespec ts;
  ts.tv_sec = static_cast<time_t>(deadline_ns / kNsPerS);
  ts.tv_nsec = static_cast<long>(deadline_ns % kNsPerS);
  // EINTR (a signal, e.g. SIGTERM): sleep again to the same absolute deadline.
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

}  // namespace

CycleClock::CycleClock(Mode mode, std::int64_t period_ns, double pace)
    : mode_(mode), period_ns_(period_ns), pace_(pace) {}

std::int64_t CycleClock::monotonic_ns() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * kNsPerS + ts.tv_nsec;
}

void CycleClock::start() { start(monotonic_ns()); }

void CycleClock::start(std::int64_t origin_ns) {
  origin_ns_ = origin_ns;
  t0_wall_ns_ = monotonic_ns();
  next_wall_ns_ = t0_wall_ns_;
  woke_wall_ns_ = t0_wall_ns_;
  cycle_ = 0;
  twin_ns_ = 0;
}

CycleClock::Tick CycleClock::wait() {
  Tick t;
  if (mode_ == Mode::kLive) {
    const std::int64_t now = monotonic_ns();
    if (cycle_ > 0 && now > next_wall_ns_) {
      // Overrun: the deadline of this cycle has passed already. Skip the periods missed.
      t.overran = true;
      t.skipped = static_cast<std::uint64_t>((now - next_wall_ns_) / period_ns_);
      next_wall_ns_ += static_cast<std::int64_t>(t.skipped) * period_ns_;
      if (now > next_wall_ns_) {
        ++t.skipped;
        next_wall_ns_ += period_ns_;
      }
    }
    sleep_until(next_wall_ns_);
    woke_wall_ns_ = monotonic_ns();
    t.latency_us = static_cast<double>(woke_wall_ns_ - next_wall_ns_) * 1e-3;
    t.now = hal::Timestamp{next_wall_ns_ - origin_ns_};
    next_wall_ns_ += period_ns_;
    ++cycle_;
    return t;
  }
  // Stepped: the twin's time is k·T.
  t.now = hal::Timestamp{twin_ns_};
  if (pace_ > 0.0) {
    const auto deadline =
        t0_wall_ns_ + static_cast<std::int64_t>(static_cast<double>(twin_ns_) / pace_);
    const std::int64_t now = monotonic_ns();
    if (cycle_ > 0 && now > deadline + period_ns_) t.overran = true;
    if (now < deadline) sleep_until(deadline);
    woke_wall_ns_ = monotonic_ns();
    t.latency_us =
        woke_wall_ns_ > deadline ? static_cast<double>(woke_wall_ns_ - deadline) * 1e-3 : 0.0;
  } else {
    woke_wall_ns_ = monotonic_ns();
  }
  twin_ns_ += period_ns_;
  ++cycle_;
  return t;
}

double CycleClock::cycle_time_us() const {
  return static_cast<double>(monotonic_ns() - woke_wall_ns_) * 1e-3;
}

}  // namespace app::loop
