// The synthetic wind generator of `drivetwin synth-scada` against its own closed forms:
// the Weibull marginal's mean and standard deviation, and the two-component correlation
// w·φ_s^L + (1−w)·φ_f^L at short, medium and day-long lags; the single AR(1) as its
// special case; the same seed giving the same series; bad parameters named.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "wind/synthetic_wind.hpp"

namespace {

using app::wind::SyntheticWind;
using app::wind::SyntheticWindParameters;

// Sample autocorrelation of x at lag L (mean and variance of the whole series).
double autocorrelation(const std::vector<double>& x, std::size_t lag) {
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(x.size());
  double var = 0.0, cov = 0.0;
  for (double v : x) var += (v - mean) * (v - mean);
  for (std::size_t i = 0; i + lag < x.size(); ++i) cov += (x[i] - mean) * (x[i + lag] - mean);
  return (cov / static_cast<double>(x.size() - lag)) / (var / static_cast<double>(x.size()));
}

// Gaussianised wind: z = Φ⁻¹(F(v)), F(v) = 1 − exp(−(v/c)^k), by bisection on Φ.
double gaussianise(double v, const SyntheticWindParameters& p) {
  const double u = 1.0 - std::exp(-std::pow(v / p.weibull_c, p.weibull_k));
  double lo = -9.0, hi = 9.0;
  for (int i = 0; i < 40; ++i) {  // 18/2^40: far below the statistics' scatter
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(-mid / std::sqrt(2.0)) < u ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

TEST(SyntheticWind, MarginalAndCorrelationFollowTheModelsClosedForms) {
  // Arrange: the Kelmarsh defaults, 10-minute rows, 6e5 rows (11 years). With a 45-row
  // correlation time there are ≈ 6e5/90 = 6 700 independent stretches: the standard error
  // of a correlation estimate is ≈ 1/√6 700 ≈ 0.012 and of the mean ≈ 2.48/√6 700 = 0.03 m/s;
  // the tolerances below are 3–4 of those (the single AR(1) gives 0.30 at lag 24, not 0.57).
  const SyntheticWindParameters p;
  SyntheticWind wind(p, 600.0, 7);
  std::vector<double> v(600000), z(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    v[i] = wind.next();
    z[i] = gaussianise(v[i], p);
  }
  // Assert: Weibull moments, mean c·Γ(1+1/k), variance c²·(Γ(1+2/k) − Γ(1+1/k)²).
  double mean = 0.0, sq = 0.0;
  for (double x : v) {
    mean += x;
    sq += x * x;
  }
  mean /= static_cast<double>(v.size());
  const double sd = std::sqrt(sq / static_cast<double>(v.size()) - mean * mean);
  const double g1 = std::tgamma(1.0 + 1.0 / p.weibull_k), g2 = std::tgamma(1.0 + 2.0 / p.weibull_k);
  EXPECT_NEAR(mean, p.weibull_c * g1, 0.1);
  EXPECT_NEAR(sd, p.weibull_c * std::sqrt(g2 - g1 * g1), 0.1);
  // The correlation of z at lags 1 (10 min), 24 (4 h), 72 (12 h) and 144 (a day), against
  // w·φ_s^L + (1−w)·φ_f^L with φ_s = e^(−600/27000), φ_f = 0.13, w = 0.968 written out here:
  // lag 1: 0.968·0.97802 + 0.032·0.13 = 0.9509; lag 24: 0.968·0.58665 = 0.5679;
  // lag 72: 0.968·0.20190 = 0.1954; lag 144: 0.968·0.04076 = 0.0395.
  EXPECT_NEAR(autocorrelation(z, 1), 0.9509, 0.01);
  EXPECT_NEAR(autocorrelation(z, 24), 0.5679, 0.045);
  EXPECT_NEAR(autocorrelation(z, 72), 0.1954, 0.045);
  EXPECT_NEAR(autocorrelation(z, 144), 0.0395, 0.045);
  EXPECT_NEAR(app::wind::synthetic_wind_correlation(p, 600.0, 24), 0.5679, 5e-4);
}

TEST(SyntheticWind, OneComponentIsTheSingleAr1AndASeedRepeatsItsSeries) {
  SyntheticWindParameters p;
  p.slow_weight = 1.0;
  p.slow_time_constant_s = -600.0 / std::log(0.951);  // φ = 0.951 per row
  SyntheticWind a(p, 600.0, 3), b(p, 600.0, 3), c(p, 600.0, 4);
  std::vector<double> z(200000);
  bool differs = false;
  for (auto& x : z) {
    const double va = a.next();
    EXPECT_EQ(va, b.next());
    differs = differs || va != c.next();
    x = gaussianise(va, p);
  }
  EXPECT_TRUE(differs);
  // AR(1): corr at lag L is 0.951^L: 0.951 and 0.951^24 = 0.2998.
  EXPECT_NEAR(autocorrelation(z, 1), 0.951, 0.01);
  EXPECT_NEAR(autocorrelation(z, 24), 0.2998, 0.05);
}

TEST(SyntheticWind, BadParametersAreNamed) {
  const char* what = nullptr;
  SyntheticWindParameters p;
  EXPECT_TRUE(app::wind::valid_synthetic_wind(p, 600.0, &what));
  p.slow_weight = 0.0;
  EXPECT_FALSE(app::wind::valid_synthetic_wind(p, 600.0, &what));
  EXPECT_NE(std::string(what).find("slow_weight"), std::string::npos);
  p = {};
  p.fast_lag1_10min = 1.0;
  EXPECT_FALSE(app::wind::valid_synthetic_wind(p, 600.0, &what));
  EXPECT_NE(std::string(what).find("fast_lag1"), std::string::npos);
  p = {};
  EXPECT_FALSE(app::wind::valid_synthetic_wind(p, 0.0, &what));
  EXPECT_NE(std::string(what).find("period"), std::string::npos);
}

}  // namespace
