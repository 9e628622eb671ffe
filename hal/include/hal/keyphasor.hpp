#pragma once
// Keyphasor: once-(or N-)per-revolution pulses of a shaft as edge time stamps,
// taken by the kernel when the edge happened (GPIO line events), so shaft speed
// and the angle reference for order tracking do not depend on when the loop
// gets to look.
//
// Thread context: read() from the RT thread: pops from a bounded lock-free
// queue filled by the backend's event thread; never blocks. KeyphasorTracker is
// a plain value type with no I/O, for the RT thread.

#include <cstdint>

#include "hal/clock.hpp"
#include "hal/device.hpp"

namespace hal {

struct KeyphasorEdge {
  Timestamp stamp{0};          // [ns] kernel time stamp of the edge (source clock)
  bool rising = true;          // edge polarity
  std::uint32_t sequence = 0;  // [-] edge counter of the backend, wraps; a jump means lost events
};

class Keyphasor : public Device {
 public:
  /// Pops the oldest edge not yet read.
  /// @return kOk; kNoData when none is waiting; kOverflow once after edges were
  ///         dropped because the queue was full (the edge returned is still valid).
  virtual Status read(KeyphasorEdge& out) = 0;
};

/// Shaft speed and phase from keyphasor edges (pure, allocation-free).
/// Speed from the last full period: f = 1 / (N·T), N pulses per revolution.
/// A period outside [min, max] speed is rejected as a glitch; no edge for longer
/// than the stale limit makes the speed invalid (a stuck keyphasor).
class KeyphasorTracker {
 public:
  struct Config {
    int pulses_per_rev = 1;                          // [-]
    double min_speed_hz = 0.01;                      // [Hz] slower → treated as stopped/stuck
    double max_speed_hz = 200.0;                     // [Hz] faster → glitch, edge ignored
    Timestamp stale_after{std::chrono::seconds(2)};  // no edge this long → invalid
    bool use_rising = true;                          // which polarity marks the reference
  };
  struct State {
    double speed_hz = 0.0;        // [rev/s] of the shaft carrying the mark
    Timestamp last_reference{0};  // [ns] last reference edge (angle 0)
    bool valid = false;
    std::uint32_t edges = 0;     // reference edges accepted
    std::uint32_t glitches = 0;  // edges rejected as too close
    std::uint32_t lost = 0;      // edges lost according to the sequence counter
  };

  KeyphasorTracker() : KeyphasorTracker(Config{}) {}
  explicit KeyphasorTracker(const Config& config) : config_(config) {}

  /// Feeds one edge. Edges must come in time order (kernel order).
  void on_edge(const KeyphasorEdge& edge);
  /// Speed/validity as of `now` (ages the estimate; does not change state).
  State state(Timestamp now) const;
  /// Shaft angle [rad, 0..2π) at `t` by linear extrapolation from the last
  /// reference edge; meaningful only while state(t).valid.
  double angle_rad(Timestamp t) const;
  void reset() {
    state_ = State{};
    have_last_seq_ = false;
    lost_at_last_edge_ = 0;
  }

 private:
  Config config_;
  State state_;
  std::uint32_t last_seq_ = 0;
  bool have_last_seq_ = false;
  std::uint32_t lost_at_last_edge_ = 0;
};

}  // namespace hal
