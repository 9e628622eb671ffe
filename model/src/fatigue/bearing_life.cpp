// ISO 281:2007 life modification factor and its inputs (see the header).
#include "model/fatigue/bearing_life.hpp"

#include "units.hpp"

#include <algorithm>
#include <cmath>

namespace model::fatigue {
namespace {
constexpr double kZeroCelsiusK = 273.15;
constexpr double kAisoMax = 50.0;  // ISO 281:2007 §9.3.1
constexpr double kKappaMin = 0.1;  // the standard's curves span 0.1 ≤ κ ≤ 4
constexpr double kKappaMax = 4.0;

double loglog(double nu) { return std::log10(std::log10(nu + 0.7)); }
}  // namespace

double kinematic_viscosity_mm2_s(double nu40, double nu100, double temperature_c) {
  // ASTM D341 (Walther): log10 log10(ν + 0.7) = A − B·log10 T, T in kelvin.
  const double t1 = std::log10(40.0 + kZeroCelsiusK), t2 = std::log10(100.0 + kZeroCelsiusK);
  const double z1 = loglog(nu40), z2 = loglog(nu100);
  const double b = (z1 - z2) / (t2 - t1);
  const double a = z1 + b * t1;
  const double z = a - b * std::log10(temperature_c + kZeroCelsiusK);
  return std::pow(10.0, std::pow(10.0, z)) - 0.7;
}

double rated_viscosity_mm2_s(double speed_rpm, double pitch_diameter_mm) {
  if (!(speed_rpm > 0.0) || !(pitch_diameter_mm > 0.0)) return 0.0;
  // ISO 281:2007 §9.3.3: ν1 = 45000·n^−0.83·D_pw^−0.5 (n < 1000 r/min), 4500·n^−0.5·D_pw^−0.5.
  const double root_dpw = std::sqrt(pitch_diameter_mm);
  return speed_rpm < 1000.0 ? 45000.0 * std::pow(speed_rpm, -0.83) / root_dpw
                            : 4500.0 / std::sqrt(speed_rpm) / root_dpw;
}

double life_modification_factor(BearingType type, double kappa, double ec_cu_over_p) {
  const double k = std::clamp(kappa, kKappaMin, kKappaMax);
  const double x = std::max(ec_cu_over_p, 0.0);
  double inner = 0.0;
  if (type == BearingType::kBall) {
    const double k1 = k < 0.4 ? 2.2649 : 1.9987;
    const double k2 = k < 0.4 ? 0.054381 : k < 1.0 ? 0.19087 : 0.071739;
    const double term = 2.5671 - k1 / std::pow(k, k2);
    inner = 1.0 - std::pow(std::max(term, 0.0), 0.83) * std::cbrt(x);
    return inner > 0.0 ? std::min(kAisoMax, 0.1 * std::pow(inner, -9.3)) : kAisoMax;
  }
  const double k1 = k < 0.4 ? 1.3993 : 1.2348;
  const double k2 = k < 0.4 ? 0.054381 : k < 1.0 ? 0.19087 : 0.071739;
  inner = 1.0 - (1.5859 - k1 / std::pow(k, k2)) * std::pow(x, 0.4);
  return inner > 0.0 ? std::min(kAisoMax, 0.1 * std::pow(inner, -9.185)) : kAisoMax;
}

double iso76_static_rating_n(const Bearing& b) {
  if (b.type != BearingType::kRoller) return 0.0;
  const double d = b.element_diameter_m * kMm, dpw = b.pitch_diameter_m * kMm;
  const double l = b.roller_effective_length_m * kMm;
  const double cos_a = std::cos(b.contact_angle_rad);
  if (!(d > 0.0 && dpw > d && l > 0.0 && b.elements > 0 && b.rows > 0 && cos_a > 0.0)) return 0.0;
  // ISO 76:2006, radial roller bearings: C0r = 44·(1 − D_we·cos α/D_pw)·i·Z·L_we·D_we·cos α.
  return 44.0 * (1.0 - d * cos_a / dpw) * b.rows * b.elements * l * d * cos_a;
}

double effective_static_rating_n(const Bearing& b) {
  return b.static_rating_n > 0.0 ? b.static_rating_n : iso76_static_rating_n(b);
}

double effective_fatigue_load_limit_n(const Bearing& b) {
  if (b.fatigue_load_limit_n > 0.0) return b.fatigue_load_limit_n;
  const double c0 = effective_static_rating_n(b);
  if (!(c0 > 0.0)) return 0.0;
  const double dpw = b.pitch_diameter_m * kMm;
  // ISO 281:2007's approximation of C_u from C0 (roller: /8.2, ball: /27; size factor above
  // D_pw = 100 mm).
  if (b.type == BearingType::kRoller) {
    return dpw <= 100.0 ? c0 / 8.2 : c0 / 8.2 * std::pow(100.0 / dpw, 0.3);
  }
  return dpw <= 100.0 ? c0 / 27.0 : c0 / 27.0 * std::pow(100.0 / dpw, 0.5);
}

}  // namespace model::fatigue
