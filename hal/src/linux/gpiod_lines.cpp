// GPIO keyphasor and digital outputs on libgpiod v1.6: see hal/gpiod_lines.hpp.
#include "hal/gpiod_lines.hpp"

#include <gpiod.h>

#include <atomic>
#include <boost/lockfree/spsc_queue.hpp>
#include <cstring>

namespace hal {
namespace {

gpiod_chip* open_chip(const std::string& ref) {
  if (ref.empty()) return nullptr;
  if (ref.front() == '/') return gpiod_chip_open(ref.c_str());
  if (gpiod_chip* c = gpiod_chip_open_by_name(ref.c_str())) return c;
  return gpiod_chip_open_by_label(ref.c_str());
}

constexpr int kEventsPerRead = 16;
constexpr long kWaitNs = 100'000'000;  // event wait tick: bounds deactivate/stop latency

}  // namespace

// ---- keyphasor -------------------------------------------------------------

struct GpiodKeyphasor::Impl {
  explicit Impl(const GpiodKeyphasorConfig& c) : config(c) {}
  GpiodKeyphasorConfig config;
  std::atomic<LifecycleState> lifecycle{LifecycleState::kUnconfigured};
  gpiod_chip* chip = nullptr;
  gpiod_line* line = nullptr;
  Thread thread;
  std::atomic<bool> stop{false};
  std::atomic<bool> active{false};
  std::atomic<bool> overflowed{false};
  std::uint32_t sequence = 0;  // event thread only
  boost::lockfree::spsc_queue<KeyphasorEdge, boost::lockfree::capacity<kKeyphasorQueueEdges>> queue;

  void run() {
    gpiod_line_event events[kEventsPerRead];
    while (!stop.load()) {
      const timespec tick{0, kWaitNs};
      const int r = gpiod_line_event_wait(line, &tick);
      if (r <= 0) continue;  // timeout (or EINTR): re-check stop
      const int n = gpiod_line_event_read_multiple(line, events, kEventsPerRead);
      for (int i = 0; i < n; ++i) {
        KeyphasorEdge e;
        e.stamp = std::chrono::seconds(events[i].ts.tv_sec) +
                  std::chrono::nanoseconds(events[i].ts.tv_nsec);
        e.rising = events[i].event_type == GPIOD_LINE_EVENT_RISING_EDGE;
        e.sequence = sequence++;  // a dropped edge below shows as a jump to the tracker
        if (!active.load()) continue;
        if (!queue.push(e)) overflowed = true;
      }
    }
  }
};

GpiodKeyphasor::GpiodKeyphasor(const GpiodKeyphasorConfig& config)
    : impl_(std::make_unique<Impl>(config)) {}

GpiodKeyphasor::~GpiodKeyphasor() {
  Impl& m = *impl_;
  if (m.thread.joinable()) {
    m.stop = true;
    m.thread.join();
  }
  if (m.line) gpiod_line_release(m.line);
  if (m.chip) gpiod_chip_close(m.chip);
}

Status GpiodKeyphasor::configure() {
  Impl& m = *impl_;
  if (m.lifecycle != LifecycleState::kUnconfigured) return Status::kWrongState;
  m.chip = open_chip(m.config.chip.chip);
  if (!m.chip) return Status::kIoError;
  m.line = gpiod_chip_get_line(m.chip, m.config.line);
  if (!m.line) return Status::kInvalidConfig;
  gpiod_line_request_config req{};
  req.consumer = m.config.consumer.c_str();
  req.request_type = m.config.both_edges ? GPIOD_LINE_REQUEST_EVENT_BOTH_EDGES
                                         : GPIOD_LINE_REQUEST_EVENT_RISING_EDGE;
  req.flags = m.config.active_low ? GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW : 0;
  if (gpiod_line_request(m.line, &req, 0) != 0) {
    m.line = nullptr;
    return Status::kIoError;
  }
  if (m.thread.start(m.config.thread, [&m] { m.run(); }) != Status::kOk) return Status::kIoError;
  m.lifecycle = LifecycleState::kInactive;
  return Status::kOk;
}

Status GpiodKeyphasor::activate() {
  Impl& m = *impl_;
  if (m.lifecycle == LifecycleState::kUnconfigured) return Status::kWrongState;
  m.active = true;
  m.lifecycle = LifecycleState::kActive;
  return Status::kOk;
}

Status GpiodKeyphasor::deactivate() {
  Impl& m = *impl_;
  if (m.lifecycle == LifecycleState::kUnconfigured) return Status::kOk;
  m.active = false;
  m.lifecycle = LifecycleState::kInactive;
  return Status::kOk;
}

LifecycleState GpiodKeyphasor::state() const { return impl_->lifecycle; }

Status GpiodKeyphasor::read(KeyphasorEdge& out) {
  Impl& m = *impl_;
  if (m.lifecycle != LifecycleState::kActive) return Status::kWrongState;
  if (!m.queue.pop(out)) return Status::kNoData;
  if (m.overflowed.exchange(false)) return Status::kOverflow;
  return Status::kOk;
}

// ---- outputs (SAFETY-CRITICAL) -----------------------------------------------

struct GpiodDigitalOutputs::Impl {
  explicit Impl(const GpiodOutputsConfig& c) : config(c) {}
  GpiodOutputsConfig config;
  std::atomic<LifecycleState> lifecycle{LifecycleState::kUnconfigured};
  gpiod_chip* chip = nullptr;
  gpiod_line* watchdog = nullptr;
  gpiod_line* alarm = nullptr;

  int alarm_level(bool raised) const {
    const bool energised = !raised;  // fail-safe relay: energised = no alarm
    return config.alarm_relay_energised_when_ok ? (energised ? 1 : 0) : (energised ? 0 : 1);
  }

  /// Drives both safe states; tries both even if one fails.
  Status safe() {
    Status s = Status::kOk;
    if (watchdog && gpiod_line_set_value(watchdog, 0) != 0) s = Status::kIoError;
    if (alarm && gpiod_line_set_value(alarm, alarm_level(true)) != 0) s = Status::kIoError;
    return s;
  }
};

GpiodDigitalOutputs::GpiodDigitalOutputs(const GpiodOutputsConfig& config)
    : impl_(std::make_unique<Impl>(config)) {}

GpiodDigitalOutputs::~GpiodDigitalOutputs() {
  Impl& m = *impl_;
  (void)m.safe();
  if (m.watchdog) gpiod_line_release(m.watchdog);
  if (m.alarm) gpiod_line_release(m.alarm);
  if (m.chip) gpiod_chip_close(m.chip);
}

Status GpiodDigitalOutputs::configure() {
  Impl& m = *impl_;
  if (m.lifecycle != LifecycleState::kUnconfigured) return Status::kWrongState;
  if (m.config.watchdog_line == m.config.alarm_line) return Status::kInvalidConfig;
  m.chip = open_chip(m.config.chip.chip);
  if (!m.chip) return Status::kIoError;
  gpiod_line* wd = gpiod_chip_get_line(m.chip, m.config.watchdog_line);
  gpiod_line* al = gpiod_chip_get_line(m.chip, m.config.alarm_line);
  if (!wd || !al) return Status::kInvalidConfig;
  // Requested straight into the safe states: no glitch to "healthy" at start-up.
  if (gpiod_line_request_output(wd, m.config.consumer.c_str(), 0) != 0) return Status::kIoError;
  m.watchdog = wd;
  if (gpiod_line_request_output(al, m.config.consumer.c_str(), m.alarm_level(true)) != 0)
    return Status::kIoError;
  m.alarm = al;
  m.lifecycle = LifecycleState::kInactive;
  return Status::kOk;
}

Status GpiodDigitalOutputs::activate() {
  Impl& m = *impl_;
  if (m.lifecycle == LifecycleState::kUnconfigured) return Status::kWrongState;
  m.lifecycle = LifecycleState::kActive;
  return Status::kOk;
}

Status GpiodDigitalOutputs::deactivate() {
  Impl& m = *impl_;
  if (m.lifecycle == LifecycleState::kActive) m.lifecycle = LifecycleState::kInactive;
  return m.safe();
}

LifecycleState GpiodDigitalOutputs::state() const { return impl_->lifecycle; }

Status GpiodDigitalOutputs::set_watchdog(bool level) {
  Impl& m = *impl_;
  if (m.lifecycle != LifecycleState::kActive) return Status::kWrongState;
  return gpiod_line_set_value(m.watchdog, level ? 1 : 0) == 0 ? Status::kOk : Status::kIoError;
}

Status GpiodDigitalOutputs::set_alarm(bool raised) {
  Impl& m = *impl_;
  if (m.lifecycle != LifecycleState::kActive) return Status::kWrongState;
  return gpiod_line_set_value(m.alarm, m.alarm_level(raised)) == 0 ? Status::kOk : Status::kIoError;
}

const ThreadReport& GpiodKeyphasor::thread_report() const { return impl_->thread.report(); }

}  // namespace hal
