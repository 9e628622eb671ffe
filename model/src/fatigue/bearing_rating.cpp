// ISO 281:2007 basic dynamic radial load ratings from bearing geometry (see the header).
#include "model/fatigue/bearing_rating.hpp"

#include "units.hpp"

#include <array>
#include <cmath>
#include <cstddef>

namespace model::fatigue {
namespace {

// ISO 281:2007 Table 7, radial roller bearings: f_c at γ = 0.01, 0.02, ..., 0.37.
constexpr double kRollerGammaStep = 0.01;
constexpr std::array<double, 37> kRollerFc{
    52.1, 60.8, 66.5, 70.7, 74.1, 76.9, 79.2, 81.2, 82.8, 84.2, 85.4, 86.4, 87.1,
    87.7, 88.2, 88.5, 88.7, 88.8, 88.8, 88.7, 88.5, 88.2, 87.9, 87.5, 87.0, 86.4,
    85.8, 85.2, 84.5, 83.8, 83.0, 82.2, 81.3, 80.4, 79.5, 78.6, 77.6};

// ISO 281:2007 Table 2, single-row radial-contact groove ball bearings: f_c at γ = 0.01 ..
// 0.10 in steps of 0.01, then 0.12 .. 0.40 in steps of 0.02.
constexpr std::array<double, 25> kBallGamma{0.01, 0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.09,
                                            0.10, 0.12, 0.14, 0.16, 0.18, 0.20, 0.22, 0.24, 0.26,
                                            0.28, 0.30, 0.32, 0.34, 0.36, 0.38, 0.40};
constexpr std::array<double, 25> kBallFc{29.1, 35.8, 40.3, 43.8, 46.7, 49.1, 51.1, 52.8, 54.3,
                                         55.5, 57.5, 58.8, 59.6, 59.9, 59.9, 59.6, 59.0, 58.2,
                                         57.1, 56.0, 54.6, 53.2, 51.7, 50.0, 48.4};

constexpr double kBmBall = 1.3;    // [-] radial (deep groove) ball bearings
constexpr double kBmRoller = 1.1;  // [-] cylindrical and tapered roller bearings
constexpr double kBallLargeDiameterMm = 25.4;
constexpr double kTolerance = 1e-12;  // γ at a table end is inside

template <std::size_t N>
double interpolate(const std::array<double, N>& x, const std::array<double, N>& y, double v) {
  if (!(v >= x.front() - kTolerance && v <= x.back() + kTolerance)) return 0.0;
  for (std::size_t i = 1; i < N; ++i) {
    if (v <= x[i]) {
      const double t = (v - x[i - 1]) / (x[i] - x[i - 1]);
      return y[i - 1] + t * (y[i] - y[i - 1]);
    }
  }
  return y.back();
}
}  // namespace

double roller_factor_fc(double gamma) {
  static constexpr std::array<double, 37> kGamma = [] {
    std::array<double, 37> g{};
    for (std::size_t i = 0; i < g.size(); ++i) g[i] = kRollerGammaStep * static_cast<double>(i + 1);
    return g;
  }();
  return interpolate(kGamma, kRollerFc, gamma);
}

double ball_factor_fc(double gamma) { return interpolate(kBallGamma, kBallFc, gamma); }

BearingRating iso281_dynamic_rating(const Bearing& b) {
  BearingRating r;
  const double d_mm = b.element_diameter_m * kMm;
  const double dpw_mm = b.pitch_diameter_m * kMm;
  const double cos_a = std::cos(b.contact_angle_rad);
  if (!(d_mm > 0.0 && dpw_mm > d_mm && b.elements > 0 && b.rows > 0 && cos_a > 0.0)) {
    r.error = "geometry incomplete (elements, rows, element and pitch diameters, contact angle)";
    return r;
  }
  r.gamma = d_mm * cos_a / dpw_mm;
  const double z = b.elements;
  const double i = b.rows;
  if (b.type == BearingType::kRoller) {
    const double l_mm = b.roller_effective_length_m * kMm;
    if (!(l_mm > 0.0)) {
      r.error = "roller_effective_length_m must be > 0 to rate a roller bearing from geometry";
      return r;
    }
    r.f_c = roller_factor_fc(r.gamma);
    if (r.f_c <= 0.0) {
      r.error = "D_we·cos α/D_pw outside 0.01..0.37 (ISO 281 Table 7 entries covered here)";
      return r;
    }
    r.b_m = kBmRoller;
    // ISO 281:2007 §7.1.1: C_r = b_m·f_c·(i·L_we·cos α)^(7/9)·Z^(3/4)·D_we^(29/27).
    r.c_n = r.b_m * r.f_c * std::pow(i * l_mm * cos_a, 7.0 / 9.0) * std::pow(z, 0.75) *
            std::pow(d_mm, 29.0 / 27.0);
  } else {
    r.f_c = ball_factor_fc(r.gamma);
    if (r.f_c <= 0.0) {
      r.error = "D_w·cos α/D_pw outside 0.01..0.40 (ISO 281 Table 2 entries covered here)";
      return r;
    }
    r.b_m = kBmBall;
    // ISO 281:2007 §6.1.1: C_r = b_m·f_c·(i·cos α)^0.7·Z^(2/3)·D_w^1.8 (D_w ≤ 25.4 mm),
    // 3.647·b_m·f_c·(i·cos α)^0.7·Z^(2/3)·D_w^1.4 (D_w > 25.4 mm).
    const double common = r.b_m * r.f_c * std::pow(i * cos_a, 0.7) * std::pow(z, 2.0 / 3.0);
    r.c_n = d_mm <= kBallLargeDiameterMm ? common * std::pow(d_mm, 1.8)
                                         : 3.647 * common * std::pow(d_mm, 1.4);
  }
  return r;
}

BearingRating effective_dynamic_rating(const Bearing& b) {
  if (b.dynamic_rating_n > 0.0) {
    BearingRating r;
    r.c_n = b.dynamic_rating_n;
    return r;
  }
  return iso281_dynamic_rating(b);
}

}  // namespace model::fatigue
