#pragma once
// One period of a periodic, dimensionless function, sampled at equal steps and
// interpolated linearly: how the dynamics model stores every time-varying
// stiffness shape (gear mesh stiffness over one mesh cycle, bearing varying
// compliance over one ball pass) and every periodic force shape. Damage terms
// plug in as tables too (a cracked tooth is a table over one gear revolution).
//
// Thread context: built off the real-time thread; value() is O(1), allocation-
// and exception-free and safe on the real-time thread.

#include <array>
#include <cmath>
#include <cstddef>

namespace model::dynamics {

struct PeriodicTable {
  /// Samples per period. 256 resolves a mesh cycle to 0.4 % of its period, and
  /// keeps a reduced model's tables (a few dozen of them) inside its memory budget.
  static constexpr std::size_t kSize = 256;

  std::array<double, kSize> values{};  // [-] f(i / kSize), i = 0 .. kSize-1

  /// f(cycles): periodic with period 1 in `cycles`, linear between samples.
  double value(double cycles) const noexcept {
    const double frac = cycles - std::floor(cycles);
    const double pos = frac * static_cast<double>(kSize);
    std::size_t i = static_cast<std::size_t>(pos);
    if (i >= kSize) i = kSize - 1;  // frac rounded up to 1.0
    const double w = pos - static_cast<double>(i);
    const std::size_t j = (i + 1 == kSize) ? 0 : i + 1;
    return values[i] + w * (values[j] - values[i]);
  }

  /// Mean over one period of the linearly interpolated function.
  double mean() const noexcept {
    double s = 0.0;
    for (double v : values) s += v;
    return s / static_cast<double>(kSize);
  }

  static PeriodicTable constant(double v) noexcept {
    PeriodicTable t;
    t.values.fill(v);
    return t;
  }

  /// 1 + relative_amplitude·cos(2π·cycles): a bearing's varying compliance.
  static PeriodicTable cosine(double relative_amplitude) noexcept {
    PeriodicTable t;
    for (std::size_t i = 0; i < kSize; ++i) {
      t.values[i] =
          1.0 + relative_amplitude * std::cos(2.0 * 3.14159265358979323846 *
                                              static_cast<double>(i) / static_cast<double>(kSize));
    }
    return t;
  }
};

}  // namespace model::dynamics
