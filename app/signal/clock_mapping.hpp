#pragma once
// Mapping between two clocks from one-way time stamps: the CMS front end's free-running
// clock (CmsBlock::stamp, unwrapped by hal) and the box's CLOCK_MONOTONIC (the block's
// arrival stamp, which is also the clock of the keyphasor edges), so that a live CMS window
// can be order-tracked against keyphasor edges.
//
// Model: arrival = a + (1 + δ)·device + latency, latency ≥ L_min (transfer, buffering and
// scheduling; random, one-sided). The latency's lower envelope is what carries the clock
// relation: per bucket of `bucket_ns` of device time the sample with the smallest
// (arrival − device) is kept (the one least delayed), and a straight line is fitted by least
// squares through the minima of the last `buckets` buckets: offset and drift δ (how a
// software PTP/NTP servo separates clock drift from queueing delay). The mapping is exact up
// to the minimum latency L_min, a constant that one-way stamps cannot reveal: it shifts the
// phase of every block equally (no effect on speed or orders); configure min_latency_ns if it
// is known. A jump of the offset beyond `reset_ns` from the fit (front end restarted, clock
// stepped) starts the estimate afresh.
//
// Thread context: add() and the conversions are O(1) or O(buckets) with fixed storage: no
// allocation, no locks (RT-safe). One owning thread.

#include <array>
#include <cstddef>
#include <cstdint>

namespace app::signal {

inline constexpr std::size_t kMaxClockBuckets = 256;

struct ClockMappingConfig {
  std::int64_t bucket_ns = 1'000'000'000;  // [ns] device time per bucket
  std::size_t buckets = 64;                // [-] buckets in the fit (≤ kMaxClockBuckets)
  std::int64_t min_latency_ns = 0;         // [ns] known minimum transport latency
  std::int64_t reset_ns = 100'000'000;     // [ns] offset jump that restarts the estimate
};

class ClockMapping {
 public:
  explicit ClockMapping(const ClockMappingConfig& config = {});

  /// One pair of stamps of the same event: device clock [ns], host clock [ns].
  void add(std::int64_t device_ns, std::int64_t host_ns) noexcept;
  /// True once two buckets have closed (a line needs two points).
  bool valid() const noexcept { return fitted_; }
  /// Host time [ns] of a device time (valid() required; else the last offset seen).
  std::int64_t to_host(std::int64_t device_ns) const noexcept;
  /// Device time [ns] of a host time.
  std::int64_t to_device(std::int64_t host_ns) const noexcept;
  /// Drift δ of the device clock against the host's [ppm] (host = (1 + δ)·device).
  double drift_ppm() const noexcept { return slope_ * 1e6; }
  std::uint64_t resets() const noexcept { return resets_; }
  void reset() noexcept;

 private:
  struct Minimum {
    std::int64_t device_ns = 0;
    std::int64_t offset_ns = 0;  // host − device
  };
  void close_bucket() noexcept;
  void fit() noexcept;

  ClockMappingConfig config_;
  std::array<Minimum, kMaxClockBuckets> ring_{};
  std::size_t head_ = 0, count_ = 0;
  bool open_ = false;
  std::int64_t bucket_index_ = 0;  // device_ns / bucket_ns of the open bucket
  Minimum current_{};              // the open bucket's minimum
  bool fitted_ = false;
  std::int64_t ref_device_ns_ = 0;  // the fit: offset(d) = ref_offset + intercept + slope·(d − ref)
  std::int64_t ref_offset_ns_ = 0;
  double intercept_ns_ = 0.0;
  double slope_ = 0.0;
  std::int64_t last_offset_ns_ = 0;
  std::uint64_t resets_ = 0;
};

}  // namespace app::signal
