#pragma once
// Backends for absent hardware (the "null" backends of the style guide) that
// remember what they were given, for tests, replays and `--sim` runs: digital
// outputs with the same safe-state semantics as the GPIO backend, and a results
// sink holding the last register image.
//
// Thread context: as the interfaces; the accessors are for the same thread
// (tests) or after the loop has stopped.

#include <cstdint>

#include "hal/digital_outputs.hpp"
#include "hal/results_sink.hpp"

namespace hal {

class MemoryDigitalOutputs final : public DigitalOutputs {
 public:
  Status configure() override {
    if (state_ != LifecycleState::kUnconfigured) return Status::kWrongState;
    state_ = LifecycleState::kInactive;
    return safe();
  }
  Status activate() override {
    if (state_ == LifecycleState::kUnconfigured) return Status::kWrongState;
    state_ = LifecycleState::kActive;
    return Status::kOk;
  }
  Status deactivate() override {
    if (state_ == LifecycleState::kActive) state_ = LifecycleState::kInactive;
    return safe();
  }
  LifecycleState state() const override { return state_; }
  Status set_watchdog(bool level) override {
    if (state_ != LifecycleState::kActive) return Status::kWrongState;
    if (level != watchdog_) ++watchdog_toggles_;
    watchdog_ = level;
    return Status::kOk;
  }
  Status set_alarm(bool raised) override {
    if (state_ != LifecycleState::kActive) return Status::kWrongState;
    alarm_raised_ = raised;
    return Status::kOk;
  }
  bool watchdog() const { return watchdog_; }
  bool alarm_raised() const { return alarm_raised_; }
  std::uint64_t watchdog_toggles() const { return watchdog_toggles_; }

 private:
  Status safe() {
    watchdog_ = false;
    alarm_raised_ = true;
    return Status::kOk;
  }
  LifecycleState state_ = LifecycleState::kUnconfigured;
  bool watchdog_ = false;
  bool alarm_raised_ = true;
  std::uint64_t watchdog_toggles_ = 0;
};

class MemoryResultsSink final : public ResultsSink {
 public:
  Status configure() override {
    state_ = LifecycleState::kInactive;
    return Status::kOk;
  }
  Status activate() override {
    if (state_ == LifecycleState::kUnconfigured) return Status::kWrongState;
    state_ = LifecycleState::kActive;
    return Status::kOk;
  }
  Status deactivate() override {
    if (state_ == LifecycleState::kActive) state_ = LifecycleState::kInactive;
    return Status::kOk;
  }
  LifecycleState state() const override { return state_; }
  Status publish(const RegisterImage& image) override {
    if (state_ != LifecycleState::kActive) return Status::kWrongState;
    last_ = image;
    ++published_;
    return Status::kOk;
  }
  const RegisterImage& last() const { return last_; }
  std::uint64_t published() const { return published_; }

 private:
  LifecycleState state_ = LifecycleState::kUnconfigured;
  RegisterImage last_{};
  std::uint64_t published_ = 0;
};

}  // namespace hal
