// The synthetic wind generator of `drivetwin synth-scada` against its own closed forms:
// the Weibull marginal's mean and standard deviation, and the two-component correlation
// w·φ_s^L + (1−w)·φ_f^L at short, medium and day-long lags; the single AR(1) as its
// special case; the annual and diurnal cycles recovered as the harmonics of the mean wind
// they put in; the same seed giving the same series; bad parameters named.
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

SyntheticWindParameters two_scale_without_cycles() {
  SyntheticWindParameters p;
  p.weibull_k = 2.60;
  p.weibull_c = 6.73;
  p.slow_weight = 0.968;
  p.slow_time_constant_s = 45 * 600.0;
  p.fast_lag1_10min = 0.13;
  p.seasonal_amplitude = 0.0;
  p.diurnal_amplitude = 0.0;
  return p;
}

TEST(SyntheticWind, MarginalAndCorrelationFollowTheModelsClosedForms) {
  // Arrange: the former Kelmarsh fit written out (k = 2.60, c = 6.73 m/s, w = 0.968, τ = 45
  // rows, φ_f = 0.13) without cycles, 10-minute rows, 6e5 rows (11 years). With a 45-row
  // correlation time there are ≈ 6e5/90 = 6 700 independent stretches: the standard error
  // of a correlation estimate is ≈ 1/√6 700 ≈ 0.012 and of the mean ≈ 2.48/√6 700 = 0.03 m/s;
  // the tolerances below are 3–4 of those (the single AR(1) gives 0.30 at lag 24, not 0.57).
  const SyntheticWindParameters p = two_scale_without_cycles();
  SyntheticWind wind(p, 600.0, 7);
  std::vector<double> v(600000), z(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    v[i] = wind.next(600.0 * static_cast<double>(i));
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
  SyntheticWindParameters p = two_scale_without_cycles();
  p.slow_weight = 1.0;
  p.slow_time_constant_s = -600.0 / std::log(0.951);  // φ = 0.951 per row
  SyntheticWind a(p, 600.0, 3), b(p, 600.0, 3), c(p, 600.0, 4);
  std::vector<double> z(200000);
  bool differs = false;
  double t = 0.0;
  for (auto& x : z) {
    const double va = a.next(t);
    EXPECT_EQ(va, b.next(t));
    differs = differs || va != c.next(t);
    x = gaussianise(va, p);
    t += 600.0;
  }
  EXPECT_TRUE(differs);
  // AR(1): corr at lag L is 0.951^L: 0.951 and 0.951^24 = 0.2998.
  EXPECT_NEAR(autocorrelation(z, 1), 0.951, 0.01);
  EXPECT_NEAR(autocorrelation(z, 24), 0.2998, 0.05);
}

TEST(SyntheticWind, AnnualAndDiurnalCyclesAreTheHarmonicsOfTheMeanWind) {
  // Arrange: cycles larger than Kelmarsh's (±25 % peaking on day 30, ±15 % peaking at 15 h
  // UTC) so that 20 years of 10-minute rows resolve them. E[v(t)] = c·Γ(1 + 1/k)·f(t) with
  // f the product of the two factors; the first harmonics of v over the day of the year and
  // the hour of the day, each divided by the mean wind, give back a_s and d_s, a_d and h_d
  // (the product's cross term averages out over the other cycle). Scatter: with a 109-row
  // correlation time, 20 years hold ≈ 1.05e6/218 ≈ 4 800 independent stretches, so an
  // amplitude estimate scatters by ≈ √2·0.41/√4 800 ≈ 0.008 (0.41 the coefficient of variation);
  // the diurnal harmonic averages over all days of each hour, the same or less.
  SyntheticWindParameters p;
  p.seasonal_amplitude = 0.25;
  p.seasonal_peak_day = 30.0;
  p.diurnal_amplitude = 0.15;
  p.diurnal_peak_hour = 15.0;
  SyntheticWind wind(p, 600.0, 11);
  const double kPi = 3.14159265358979323846;
  const double t0 = 1420070400.0;  // 2015-01-01T00:00:00Z
  double sum = 0.0, cs = 0.0, ss = 0.0, cd = 0.0, sd = 0.0;
  const std::size_t n = 1051920;  // 20 years
  for (std::size_t i = 0; i < n; ++i) {
    const double t = t0 + 600.0 * static_cast<double>(i);
    const double v = wind.next(t);
    const double day = std::fmod(t / 86400.0, 365.25);
    const double hour = 24.0 * (t / 86400.0 - std::floor(t / 86400.0));
    sum += v;
    cs += v * std::cos(2 * kPi * day / 365.25);
    ss += v * std::sin(2 * kPi * day / 365.25);
    cd += v * std::cos(2 * kPi * hour / 24.0);
    sd += v * std::sin(2 * kPi * hour / 24.0);
  }
  // Act: amplitude 2·|Σ v·e^(iωt)|/Σ v, peak at the phase.
  const double a_s = 2.0 * std::hypot(cs, ss) / sum, a_d = 2.0 * std::hypot(cd, sd) / sum;
  const double peak_day = std::fmod(std::atan2(ss, cs) * 365.25 / (2 * kPi) + 365.25, 365.25);
  const double peak_hour = std::fmod(std::atan2(sd, cd) * 24.0 / (2 * kPi) + 24.0, 24.0);
  // Assert: within 3 scatters; the peak within 0.03/0.25 rad of the year (≈ 7 days) and
  // 0.03/0.15 rad of the day (≈ 0.8 h).
  EXPECT_NEAR(a_s, 0.25, 0.025);
  EXPECT_NEAR(peak_day, 30.0, 7.0);
  EXPECT_NEAR(a_d, 0.15, 0.025);
  EXPECT_NEAR(peak_hour, 15.0, 0.8);
  EXPECT_NEAR(sum / static_cast<double>(n), p.weibull_c * std::tgamma(1.0 + 1.0 / p.weibull_k),
              0.15);
  // The factor itself at a peak and a trough.
  EXPECT_NEAR(wind.cycle_factor(t0 + 30.0 * 86400.0 + 15.0 * 3600.0), 1.25 * 1.15, 1e-3);
  EXPECT_NEAR(wind.cycle_factor(t0 + 213.0 * 86400.0 + 3.0 * 3600.0), 0.75 * 0.85, 2e-3);
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
  p.seasonal_amplitude = 1.0;  // the scale would reach 0
  EXPECT_FALSE(app::wind::valid_synthetic_wind(p, 600.0, &what));
  EXPECT_NE(std::string(what).find("seasonal_amplitude"), std::string::npos);
  p = {};
  p.diurnal_peak_hour = std::nan("");
  EXPECT_FALSE(app::wind::valid_synthetic_wind(p, 600.0, &what));
  EXPECT_NE(std::string(what).find("diurnal_peak_hour"), std::string::npos);
  p = {};
  EXPECT_FALSE(app::wind::valid_synthetic_wind(p, 0.0, &what));
  EXPECT_NE(std::string(what).find("period"), std::string::npos);
}

}  // namespace
