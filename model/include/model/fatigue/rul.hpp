#pragma once
// Remaining useful life from accumulated Palmgren–Miner damage and its rate.
//
// The damage history is kept as increments per fixed interval (e.g. one day). From it:
//   long-term rate  = Σ ΔD / (intervals · interval)           (all history)
//   short-term rate = mean of the last `short_window` intervals
//   band            = 10th and 90th percentile of the rates over every run of
//                     `short_window` consecutive intervals (how much the rate has varied)
//   RUL = (1 − D)/rate: central value from the long-term rate, the short-term value, and a
//   band from the percentile rates (high rate → low RUL). Miner's D_crit = 1.
//
// Thread context: DamageRateHistory::add_interval() is O(1), allocation-free (fixed ring,
// oldest interval dropped when full, counted in the long-term sums); estimate() sorts a
// copy of the window rates: call it off the real-time thread.

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>

namespace model::fatigue {

inline constexpr std::size_t kMaxRateIntervals = 4096;  // 11 years of days

struct RulEstimate {
  double damage = 0.0;                                     // [-] D now
  double long_term_rate_per_s = 0.0;                       // [1/s]
  double short_term_rate_per_s = 0.0;                      // [1/s]
  double rate_p10_per_s = 0.0;                             // [1/s]
  double rate_p90_per_s = 0.0;                             // [1/s]
  double rul_s = std::numeric_limits<double>::infinity();  // [s] central (long-term rate)
  double rul_short_term_s = std::numeric_limits<double>::infinity();  // [s]
  double rul_low_s = std::numeric_limits<double>::infinity();         // [s] at the p90 rate
  double rul_high_s = std::numeric_limits<double>::infinity();        // [s] at the p10 rate
};

/// (1 − D)/rate [s]; 0 when D ≥ 1; +inf when rate ≤ 0.
double time_to_failure_s(double damage, double rate_per_s);

class DamageRateHistory {
 public:
  DamageRateHistory(double interval_s, std::size_t short_window);
  void add_interval(double damage_increment);
  std::size_t size() const { return count_; }
  RulEstimate estimate(double damage_now) const;

  // Persistence (the app writes these with its state record): the intervals held, oldest
  // first, and the long-term sums (which also count intervals dropped from the ring).
  double interval_s() const { return interval_s_; }
  std::size_t short_window() const { return short_window_; }
  /// Interval i of size(), oldest first [-].
  double increment(std::size_t i) const;
  double total_increment() const { return total_increment_; }
  std::uint64_t total_intervals() const { return total_intervals_; }
  /// Replaces the history by `n` increments (oldest first; only the newest
  /// kMaxRateIntervals kept) and the long-term sums. False (history unchanged) when the
  /// sums cannot hold them (total_intervals < n) or a value is not finite.
  /// Allocation-free.
  bool restore(const double* increments, std::size_t n, double total_increment,
               std::uint64_t total_intervals);

 private:
  double interval_s_;
  std::size_t short_window_;
  std::array<double, kMaxRateIntervals> ring_{};
  std::size_t head_ = 0, count_ = 0;
  double total_increment_ = 0.0;
  std::uint64_t total_intervals_ = 0;
};

}  // namespace model::fatigue
