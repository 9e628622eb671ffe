#include "model/fatigue/rul.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace model::fatigue {

double time_to_failure_s(double damage, double rate_per_s) {
  if (damage >= 1.0) return 0.0;
  if (!(rate_per_s > 0.0)) return std::numeric_limits<double>::infinity();
  return (1.0 - damage) / rate_per_s;
}

DamageRateHistory::DamageRateHistory(double interval_s, std::size_t short_window)
    : interval_s_(interval_s),
      short_window_(std::clamp<std::size_t>(short_window, 1, kMaxRateIntervals)) {}

void DamageRateHistory::add_interval(double inc) {
  ring_[head_] = inc;
  head_ = (head_ + 1) % kMaxRateIntervals;
  count_ = std::min(count_ + 1, kMaxRateIntervals);
  total_increment_ += inc;
  ++total_intervals_;
}

double DamageRateHistory::increment(std::size_t i) const {
  const std::size_t start = (head_ + kMaxRateIntervals - count_) % kMaxRateIntervals;
  return ring_[(start + i) % kMaxRateIntervals];
}

bool DamageRateHistory::restore(const double* increments, std::size_t n, double total_increment,
                                std::uint64_t total_intervals) {
  if (total_intervals < n || !std::isfinite(total_increment)) return false;
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(increments[i])) return false;
  const std::size_t keep = std::min(n, kMaxRateIntervals);
  for (std::size_t i = 0; i < keep; ++i) ring_[i] = increments[n - keep + i];
  count_ = keep;
  head_ = keep % kMaxRateIntervals;
  total_increment_ = total_increment;
  total_intervals_ = total_intervals;
  return true;
}

RulEstimate DamageRateHistory::estimate(double damage_now) const {
  RulEstimate e;
  e.damage = damage_now;
  if (total_intervals_ == 0) return e;
  e.long_term_rate_per_s = total_increment_ / (static_cast<double>(total_intervals_) * interval_s_);
  // Oldest-first copy of the ring.
  std::vector<double> v(count_);
  const std::size_t start = (head_ + kMaxRateIntervals - count_) % kMaxRateIntervals;
  for (std::size_t i = 0; i < count_; ++i) v[i] = ring_[(start + i) % kMaxRateIntervals];
  const std::size_t w = std::min(short_window_, count_);
  double sum = 0.0;
  for (std::size_t i = count_ - w; i < count_; ++i) sum += v[i];
  e.short_term_rate_per_s = sum / (static_cast<double>(w) * interval_s_);
  // Rolling-window rates.
  std::vector<double> rates;
  double run = 0.0;
  for (std::size_t i = 0; i < count_; ++i) {
    run += v[i];
    if (i >= w) run -= v[i - w];
    if (i + 1 >= w) rates.push_back(run / (static_cast<double>(w) * interval_s_));
  }
  std::sort(rates.begin(), rates.end());
  auto pct = [&rates](double p) {
    const double pos = p * static_cast<double>(rates.size() - 1);
    const auto lo = static_cast<std::size_t>(pos);
    const std::size_t hi = std::min(lo + 1, rates.size() - 1);
    return rates[lo] + (pos - static_cast<double>(lo)) * (rates[hi] - rates[lo]);
  };
  e.rate_p10_per_s = pct(0.10);
  e.rate_p90_per_s = pct(0.90);
  e.rul_s = time_to_failure_s(damage_now, e.long_term_rate_per_s);
  e.rul_short_term_s = time_to_failure_s(damage_now, e.short_term_rate_per_s);
  e.rul_low_s = time_to_failure_s(damage_now, e.rate_p90_per_s);
  e.rul_high_s = time_to_failure_s(damage_now, e.rate_p10_per_s);
  return e;
}

}  // namespace model::fatigue
