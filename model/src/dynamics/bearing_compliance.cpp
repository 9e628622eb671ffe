#include "model/dynamics/bearing_compliance.hpp"

#include <cmath>
#include <numbers>

namespace model::dynamics {

double rolling_contact_exponent(BearingType type) noexcept {
  return type == BearingType::kBall ? 1.5 : 10.0 / 9.0;
}

PeriodicTable bearing_load_zone_force(int elements, BearingType type) noexcept {
  PeriodicTable t;
  if (elements < 1) return PeriodicTable::constant(1.0);
  const double n = rolling_contact_exponent(type);
  const double pitch = 2.0 * std::numbers::pi / static_cast<double>(elements);
  for (std::size_t i = 0; i < PeriodicTable::kSize; ++i) {
    const double psi0 = pitch * static_cast<double>(i) / static_cast<double>(PeriodicTable::kSize);
    double f = 0.0;
    for (int j = 0; j < elements; ++j) {
      const double c = std::cos(psi0 + pitch * static_cast<double>(j));
      if (c > 0.0) f += std::pow(c, n + 1.0);
    }
    t.values[i] = f;
  }
  const double mean = t.mean();
  for (double& v : t.values) v /= mean;
  return t;
}

PeriodicTable bearing_stiffness_shape(int elements, BearingType type, double scale,
                                      double cosine_amplitude) noexcept {
  PeriodicTable t = bearing_load_zone_force(elements, type);
  const PeriodicTable c = PeriodicTable::cosine(cosine_amplitude);
  for (std::size_t i = 0; i < PeriodicTable::kSize; ++i)
    t.values[i] = c.values[i] + scale * (t.values[i] - 1.0);  // scale 0: the cosine bit for bit
  return t;
}

}  // namespace model::dynamics
