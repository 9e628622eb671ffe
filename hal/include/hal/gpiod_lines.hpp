#pragma once
// GPIO backends on libgpiod v1 (Debian 12: 1.6): the keyphasor input as edge
// events with kernel time stamps, and the digital outputs (watchdog, alarm
// relay). libgpiod types stay in the .cpp.
//
// Kernel time stamps: GPIO line events are stamped with CLOCK_MONOTONIC
// (Linux ≥ 5.7), the clock of hal::MonotonicClock, so edges and loop time compare directly.
//
// Thread context: GpiodKeyphasor::read from the RT thread (lock-free queue
// filled by an event thread); GpiodDigitalOutputs::set_* from the RT thread
// (one GPIO ioctl each, bounded, no allocation); lifecycle calls from the
// control thread.

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "hal/digital_outputs.hpp"
#include "hal/keyphasor.hpp"
#include "hal/thread.hpp"

namespace hal {

struct GpioChipRef {
  /// "/dev/gpiochip0", "gpiochip0" or a chip label (as gpiodetect prints it).
  std::string chip = "/dev/gpiochip0";
};

struct GpiodKeyphasorConfig {
  GpioChipRef chip;
  unsigned line = 0;        // line offset on the chip
  bool both_edges = false;  // false: rising edges only
  bool active_low = false;
  std::string consumer = "drivetwin-keyphasor";
  // The edge-event thread (app/ passes its thread table's entry).
  ThreadAttributes thread{"dt-keyphasor", SchedPolicy::kOther, 0, -1, 0};
};

/// Edges the queue between the event thread and the RT thread holds; when full
/// the newest edges are dropped and read() reports kOverflow once.
inline constexpr std::size_t kKeyphasorQueueEdges = 256;

class GpiodKeyphasor final : public Keyphasor {
 public:
  explicit GpiodKeyphasor(const GpiodKeyphasorConfig& config);
  ~GpiodKeyphasor() override;
  GpiodKeyphasor(const GpiodKeyphasor&) = delete;
  GpiodKeyphasor& operator=(const GpiodKeyphasor&) = delete;

  /// Opens the chip and requests the line for edge events; starts the event thread.
  Status configure() override;
  Status activate() override;
  Status deactivate() override;
  LifecycleState state() const override;
  Status read(KeyphasorEdge& out) override;
  /// What the OS granted the I/O thread (valid after configure(); warning names refusals).
  const ThreadReport& thread_report() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct GpiodOutputsConfig {
  GpioChipRef chip;
  unsigned watchdog_line = 1;
  unsigned alarm_line = 2;
  /// Relay wiring: true (default) = the relay is energised (line high) when
  /// there is NO alarm, so the safe state (alarm raised) is line low.
  bool alarm_relay_energised_when_ok = true;
  std::string consumer = "drivetwin-outputs";
};

/// SAFETY-CRITICAL: see digital_outputs.hpp for the safe states.
class GpiodDigitalOutputs final : public DigitalOutputs {
 public:
  explicit GpiodDigitalOutputs(const GpiodOutputsConfig& config);
  /// Drives the safe states, then releases the lines.
  ~GpiodDigitalOutputs() override;
  GpiodDigitalOutputs(const GpiodDigitalOutputs&) = delete;
  GpiodDigitalOutputs& operator=(const GpiodDigitalOutputs&) = delete;

  /// Requests both lines as outputs, initialised to the safe states.
  Status configure() override;
  Status activate() override;
  /// Safe states: watchdog low, alarm raised. Lines stay held.
  Status deactivate() override;
  LifecycleState state() const override;
  Status set_watchdog(bool level) override;
  Status set_alarm(bool raised) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hal
