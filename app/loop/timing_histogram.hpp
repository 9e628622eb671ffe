#pragma once
// The loop's timing distribution for the timing benchmark (tools/rt_bench/run.sh): wake-up
// latency and cycle time of every cycle in fixed 1 µs bins, so that p50 / p99 / p99.9 and
// the maximum of a 10-minute run come out exactly (to the bin), like cyclictest's histogram.
//
// Thread context: add() on the RT thread (fixed arrays, no allocation, no lock); read the
// results after the loop stopped.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>

namespace app::loop {

class TimingHistogram {
 public:
  static constexpr std::size_t kBins = 20000;  // [µs] 0 … 20 ms in 1 µs bins; beyond: overflow

  TimingHistogram() : latency_(std::make_unique<Bins>()), cycle_(std::make_unique<Bins>()) {}

  /// One cycle: wake-up latency and compute time [µs]; `late`: woke later than a period
  /// after its deadline (the cycle overran).
  void add(double latency_us, double cycle_us, bool late) noexcept {
    put(*latency_, latency_us);
    put(*cycle_, cycle_us);
    ++cycles_;
    if (late) ++late_;
  }
  /// The q-quantile (0…1) [µs] (the upper edge of its bin; the maximum for q = 1).
  double latency_quantile_us(double q) const { return quantile(*latency_, q); }
  double cycle_quantile_us(double q) const { return quantile(*cycle_, q); }
  double latency_max_us() const { return latency_->max_us; }
  double cycle_max_us() const { return cycle_->max_us; }
  std::uint64_t cycles() const { return cycles_; }
  std::uint64_t late() const { return late_; }
  /// Cycles whose wake-up latency exceeded `us`.
  std::uint64_t latency_above(double us) const;

 private:
  struct Bins {
    std::array<std::uint64_t, kBins + 1> n{};
    double max_us = 0.0;
  };
  static void put(Bins& b, double us) noexcept {
    if (!(us >= 0.0)) us = 0.0;
    const auto i = us < static_cast<double>(kBins) ? static_cast<std::size_t>(us) : kBins;
    ++b.n[i];
    if (us > b.max_us) b.max_us = us;
  }
  double quantile(const Bins& b, double q) const;

  std::unique_ptr<Bins> latency_, cycle_;
  std::uint64_t cycles_ = 0, late_ = 0;
};

}  // namespace app::loop
