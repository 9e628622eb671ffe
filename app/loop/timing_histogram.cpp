// The loop's timing distribution: see timing_histogram.hpp.
#include "loop/timing_histogram.hpp"

#include <cmath>

namespace app::loop {

double TimingHistogram::quantile(const Bins& b, double q) const {
  if (cycles_ == 0) return 0.0;
  if (q >= 1.0) return b.max_us;
  const auto rank = static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(cycles_)));
  std::uint64_t seen = 0;
  for (std::size_t i = 0; i <= kBins; ++i) {
    seen += b.n[i];
    if (seen >= rank) return i < kBins ? static_cast<double>(i + 1) : b.max_us;
  }
  return b.max_us;
}

std::uint64_t TimingHistogram::latency_above(double us) const {
  std::uint64_t n = 0;
  for (std::size_t i = 0; i <= kBins; ++i)
    if (static_cast<double>(i) >= us) n += latency_->n[i];
  return n;
}

}  // namespace app::loop
