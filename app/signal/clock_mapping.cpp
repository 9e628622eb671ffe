#include "signal/clock_mapping.hpp"

#include <algorithm>
#include <cmath>

namespace app::signal {

ClockMapping::ClockMapping(const ClockMappingConfig& config) : config_(config) {
  config_.buckets = std::clamp<std::size_t>(config_.buckets, 2, kMaxClockBuckets);
  if (config_.bucket_ns <= 0) config_.bucket_ns = 1'000'000'000;
}

void ClockMapping::reset() noexcept {
  head_ = count_ = 0;
  open_ = false;
  fitted_ = false;
  slope_ = 0.0;
  intercept_ns_ = 0.0;
}

void ClockMapping::add(std::int64_t device_ns, std::int64_t host_ns) noexcept {
  const std::int64_t offset = host_ns - device_ns;
  if (fitted_) {
    // Below the fitted envelope (a latency cannot be negative) by more than reset_ns, or ten
    // times that above it (queueing does not last a second): the front end restarted or its
    // clock was stepped.
    const std::int64_t predicted = to_host(device_ns) + config_.min_latency_ns - device_ns;
    if (offset < predicted - config_.reset_ns || offset > predicted + 10 * config_.reset_ns) {
      reset();
      ++resets_;
    }
  }
  last_offset_ns_ = offset;
  const std::int64_t index = device_ns / config_.bucket_ns;
  if (open_ && index != bucket_index_) {
    if (index < bucket_index_) {  // device time went backwards: a restart
      reset();
      ++resets_;
    } else {
      close_bucket();
    }
  }
  if (!open_) {
    open_ = true;
    bucket_index_ = index;
    current_ = {device_ns, offset};
    return;
  }
  if (offset < current_.offset_ns) current_ = {device_ns, offset};
}

void ClockMapping::close_bucket() noexcept {
  ring_[head_] = current_;
  head_ = (head_ + 1) % config_.buckets;
  count_ = std::min(count_ + 1, config_.buckets);
  open_ = false;
  fit();
}

void ClockMapping::fit() noexcept {
  if (count_ < 2) return;
  // Oldest minimum as the reference keeps the sums small (exact in double).
  const std::size_t oldest = (head_ + config_.buckets - count_) % config_.buckets;
  const Minimum ref = ring_[oldest];
  double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
  for (std::size_t k = 0; k < count_; ++k) {
    const Minimum& m = ring_[(oldest + k) % config_.buckets];
    const double x = static_cast<double>(m.device_ns - ref.device_ns);
    const double y = static_cast<double>(m.offset_ns - ref.offset_ns);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  const double n = static_cast<double>(count_);
  const double den = n * sxx - sx * sx;
  if (!(den > 0.0)) return;
  slope_ = (n * sxy - sx * sy) / den;
  intercept_ns_ = (sy - slope_ * sx) / n;
  ref_device_ns_ = ref.device_ns;
  ref_offset_ns_ = ref.offset_ns;
  fitted_ = true;
}

std::int64_t ClockMapping::to_host(std::int64_t device_ns) const noexcept {
  if (!fitted_) return device_ns + last_offset_ns_;
  const double dx = static_cast<double>(device_ns - ref_device_ns_);
  const auto offset = static_cast<std::int64_t>(std::llround(intercept_ns_ + slope_ * dx));
  // The envelope is the offset of the least delayed blocks: the event itself happened the
  // minimum latency earlier.
  return device_ns + ref_offset_ns_ + offset - config_.min_latency_ns;
}

std::int64_t ClockMapping::to_device(std::int64_t host_ns) const noexcept {
  if (!fitted_) return host_ns - last_offset_ns_;
  // host = d + R + c + s·(d − d_ref) − L  ⇒  d − d_ref = (host − R + L − d_ref − c)/(1 + s)
  const double rhs =
      static_cast<double>(host_ns - ref_offset_ns_ + config_.min_latency_ns - ref_device_ns_) -
      intercept_ns_;
  return ref_device_ns_ + static_cast<std::int64_t>(std::llround(rhs / (1.0 + slope_)));
}

}  // namespace app::signal
