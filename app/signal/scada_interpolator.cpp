// The ROM's inputs from SCADA point samples: see scada_interpolator.hpp.
#include "signal/scada_interpolator.hpp"

#include <algorithm>
#include <cmath>

namespace app::signal {

ScadaInterpolator::ScadaInterpolator(double period_s)
    : period_s_(period_s > 0.0 ? period_s : 1.0), delay_s_(2.0 * period_s_) {}

const ScadaInterpolator::Point& ScadaInterpolator::point(std::size_t i) const {
  return ring_[(head_ + kCapacity - count_ + i) % kCapacity];
}

void ScadaInterpolator::push(const Point& p) {
  ring_[head_] = p;
  head_ = (head_ + 1) % kCapacity;
  count_ = std::min(count_ + 1, kCapacity);
}

void ScadaInterpolator::sample(hal::Timestamp stamp, const model::dynamics::RomInputs& in) {
  const double t = 1e-9 * static_cast<double>(stamp.count());
  const Point p{t, {in.rotor_speed_rpm, in.input_torque_nm}};
  if (count_ > 0) {
    const Point& last = point(count_ - 1);
    if (!(t > last.t)) {
      ++ignored_;
      return;
    }
    // After a gap: hold the last value until one period before the new sample.
    if (t - last.t > 1.5 * period_s_) push(Point{t - period_s_, {last.v[0], last.v[1]}});
  }
  push(p);
}

// Fritsch–Carlson tangent at sample k (non-uniform spacing; Fritsch & Butland's weighted
// harmonic mean): 0 at a local extreme or a flat side, one-sided at the ends.
double ScadaInterpolator::tangent(std::size_t k, int c) const {
  const auto slope = [&](std::size_t a) {
    const Point& p0 = point(a);
    const Point& p1 = point(a + 1);
    return (p1.v[c] - p0.v[c]) / (p1.t - p0.t);
  };
  if (count_ < 2) return 0.0;
  if (k == 0) return slope(0);
  if (k + 1 >= count_) return slope(k - 1);
  const double d0 = slope(k - 1), d1 = slope(k);
  if (d0 * d1 <= 0.0) return 0.0;
  const double h0 = point(k).t - point(k - 1).t, h1 = point(k + 1).t - point(k).t;
  const double w1 = 2.0 * h1 + h0, w2 = h1 + 2.0 * h0;
  return (w1 + w2) / (w1 / d0 + w2 / d1);
}

model::dynamics::RomInputs ScadaInterpolator::at(hal::Timestamp now) const {
  if (count_ == 0) return {};
  const double x = 1e-9 * static_cast<double>(now.count()) - delay_s_;
  const Point& first = point(0);
  const Point& last = point(count_ - 1);
  if (x <= first.t) return {first.v[0], first.v[1]};
  if (x >= last.t) return {last.v[0], last.v[1]};
  std::size_t k = 0;
  while (k + 2 < count_ && point(k + 1).t <= x) ++k;
  const Point& a = point(k);
  const Point& b = point(k + 1);
  const double h = b.t - a.t, s = (x - a.t) / h;
  const double s2 = s * s, s3 = s2 * s;
  const double h00 = 2.0 * s3 - 3.0 * s2 + 1.0, h10 = s3 - 2.0 * s2 + s;
  const double h01 = -2.0 * s3 + 3.0 * s2, h11 = s3 - s2;
  double v[2];
  for (int c = 0; c < 2; ++c)
    v[c] = h00 * a.v[c] + h10 * h * tangent(k, c) + h01 * b.v[c] + h11 * h * tangent(k + 1, c);
  return {v[0], v[1]};
}

}  // namespace app::signal
