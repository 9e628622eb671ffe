// Shaft speed from keyphasor edges: f = 1 / (N · T) for N marks per revolution
// and T the time between consecutive reference edges.
#include <cmath>
#include <numbers>

#include "hal/keyphasor.hpp"

namespace hal {

void KeyphasorTracker::on_edge(const KeyphasorEdge& edge) {
  if (have_last_seq_) {
    const std::uint32_t step = edge.sequence - last_seq_;  // wraps by design
    if (step > 1 && step < 0x80000000u) state_.lost += step - 1;
  }
  last_seq_ = edge.sequence;
  have_last_seq_ = true;
  if (edge.rising != config_.use_rising) return;

  if (state_.edges == 0) {
    state_.last_reference = edge.stamp;
    state_.edges = 1;
    lost_at_last_edge_ = state_.lost;
    return;
  }
  const double period_s = std::chrono::duration<double>(edge.stamp - state_.last_reference).count();
  const double n = static_cast<double>(config_.pulses_per_rev);
  // Too close to the previous edge for the fastest allowed speed: contact bounce or noise.
  if (period_s <= 0.0 || 1.0 / (n * period_s) > config_.max_speed_hz) {
    ++state_.glitches;
    return;
  }
  const double speed_hz = 1.0 / (n * period_s);
  state_.last_reference = edge.stamp;
  ++state_.edges;
  // After lost edges (sequence jump, or a period longer than the slowest speed)
  // the period spans several revolutions: restart the estimate from this edge.
  const bool lost_between = state_.lost != lost_at_last_edge_;
  lost_at_last_edge_ = state_.lost;
  if (speed_hz < config_.min_speed_hz || lost_between) {
    state_.valid = false;
    return;
  }
  state_.speed_hz = speed_hz;
  state_.valid = true;
}

KeyphasorTracker::State KeyphasorTracker::state(Timestamp now) const {
  State s = state_;
  if (s.edges < 2) s.valid = false;
  if (now - s.last_reference > config_.stale_after) s.valid = false;
  // A shaft slower than min_speed_hz would not have produced an edge by now either.
  if (s.valid && s.speed_hz > 0.0) {
    const double since_s = std::chrono::duration<double>(now - s.last_reference).count();
    if (since_s * s.speed_hz * static_cast<double>(config_.pulses_per_rev) > 2.0) s.valid = false;
  }
  return s;
}

double KeyphasorTracker::angle_rad(Timestamp t) const {
  const double dt_s = std::chrono::duration<double>(t - state_.last_reference).count();
  double turns = state_.speed_hz * dt_s;
  turns -= std::floor(turns);
  return 2.0 * std::numbers::pi * turns;
}

}  // namespace hal
