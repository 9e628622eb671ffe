// IEC 61400-1 normal turbulence with the Kaimal spectrum (model/wind/turbulence.hpp):
// σ1 and L against the standard's numbers by hand, the spectrum against its own closed-form
// integral, and the generated series against the target: variance σ1² and zero mean within
// each row, the periodogram's shape against S(f) at several frequencies (computed here by a
// direct DFT, not the generator's FFT), seeds, cross-fades.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <random>
#include <vector>

#include "model/wind/turbulence.hpp"

namespace {
using model::wind::TurbulenceClass;
using model::wind::TurbulenceSettings;
using model::wind::TurbulentWind;

// One row's fluctuation (no cross-fade) as a vector.
std::vector<double> segment(const TurbulentWind& w) {
  std::vector<double> u(w.samples_per_segment());
  for (std::size_t j = 0; j < u.size(); ++j) u[j] = w.fluctuation_mps(j);
  return u;
}

// One-sided periodogram at harmonic k by a direct DFT: (2/n²)·|Σ u_j e^{−2πijk/n}|² / Δf.
double periodogram(const std::vector<double>& u, std::size_t k, double segment_s) {
  const auto n = static_cast<double>(u.size());
  std::complex<double> sum = 0.0;
  for (std::size_t j = 0; j < u.size(); ++j) {
    sum += u[j] * std::polar(1.0, -2.0 * std::numbers::pi * static_cast<double>(j * k) / n);
  }
  return 2.0 * std::norm(sum) / (n * n) * segment_s;
}

TEST(Turbulence, NtmSigmaAndLengthScaleByHand) {
  // IEC 61400-1 ed. 3: σ1 = I_ref·(0.75·V + 5.6); at 15 m/s class A: 0.16·16.85 = 2.696 m/s.
  EXPECT_NEAR(model::wind::ntm_sigma_mps(TurbulenceClass::kA, 15.0), 2.696, 1e-12);
  EXPECT_NEAR(model::wind::ntm_sigma_mps(TurbulenceClass::kB, 6.75), 0.14 * 10.6625, 1e-12);
  EXPECT_NEAR(model::wind::ntm_sigma_mps(TurbulenceClass::kC, 10.0), 0.12 * 13.1, 1e-12);
  // L = 8.1·Λ1, Λ1 = 42 m at hub heights ≥ 60 m, 0.7·z below.
  EXPECT_NEAR(model::wind::kaimal_length_scale_m(80.0), 340.2, 1e-9);
  EXPECT_NEAR(model::wind::kaimal_length_scale_m(60.0), 340.2, 1e-9);
  EXPECT_NEAR(model::wind::kaimal_length_scale_m(50.0), 8.1 * 35.0, 1e-9);
}

TEST(Turbulence, KaimalIntegralMatchesClosedForm) {
  // ∫_0^F S df = σ²·[1 − (1 + 6·F·L/V)^(−2/3)]; → σ² as F → ∞.
  const double sigma = 1.7, length = 340.2, v = 6.75;
  const double tau = length / v;
  for (const double f_max : {0.01, 0.1, 2.0}) {
    // Simpson on a log-spaced grid in f (the spectrum spans decades).
    const int n = 20000;
    const double a = 1e-7, b = f_max;
    double sum = 0.0;
    const double h = std::log(b / a) / n;
    for (int i = 0; i <= n; ++i) {
      const double f = a * std::exp(h * i);
      const double w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
      sum += w * model::wind::kaimal_psd(f, sigma, length, v) * f;  // df = f·d(ln f)
    }
    const double integral = sum * h / 3.0 + model::wind::kaimal_psd(0.0, sigma, length, v) * a;
    const double expected = sigma * sigma * (1.0 - std::pow(1.0 + 6.0 * f_max * tau, -2.0 / 3.0));
    EXPECT_NEAR(integral / expected, 1.0, 1e-6) << "F = " << f_max;
  }
}

TEST(Turbulence, RowHasTargetSigmaZeroMeanAndKaimalShape) {
  TurbulenceSettings s;  // class A, 80 m hub, 600 s rows of 0.25 s samples
  TurbulentWind w(s, 7);
  const double v = 6.75;
  w.advance(v, v);
  const std::vector<double> u = segment(w);
  ASSERT_EQ(u.size(), 2400u);
  const double sigma = model::wind::ntm_sigma_mps(TurbulenceClass::kA, v);  // 1.706 m/s
  double mean = 0.0, var = 0.0;
  for (const double x : u) mean += x;
  mean /= static_cast<double>(u.size());
  for (const double x : u) var += (x - mean) * (x - mean);
  var /= static_cast<double>(u.size());
  // Harmonics over whole periods: mean and variance hold exactly, up to rounding.
  EXPECT_LT(std::abs(mean), 1e-12 * sigma);
  EXPECT_NEAR(var / (sigma * sigma), 1.0, 1e-10);

  // Periodogram = g²·S(f_k) with g² = σ²/Σ_k S(f_k)·Δf (the row's variance scaling): the
  // shape is Kaimal's at every harmonic (deterministic amplitudes, random phases).
  const double length = model::wind::kaimal_length_scale_m(s.hub_height_m);
  const double df = 1.0 / s.segment_s;
  double discrete = 0.0;
  for (std::size_t k = 1; k < u.size() / 2; ++k)
    discrete += model::wind::kaimal_psd(static_cast<double>(k) * df, sigma, length, v) * df;
  const double g2 = sigma * sigma / discrete;
  // The harmonics k = 1 … n/2−1 stand for Kaimal's spectrum between Δf/2 and the Nyquist
  // frequency (midpoint rule): σ²·[(1 + 6·(Δf/2)·L/V)^(−2/3) − (1 + 6·f_N·L/V)^(−2/3)] = 0.847·σ²
  // here; the rule's error on this convex spectrum, mostly in the first bins, is ≲ 2 %.
  const double tau = length / v;
  const double band = std::pow(1.0 + 6.0 * 0.5 * df * tau, -2.0 / 3.0) -
                      std::pow(1.0 + 6.0 * 2.0 * tau, -2.0 / 3.0);
  EXPECT_NEAR(discrete / (sigma * sigma) / band, 1.0, 0.02);
  for (const std::size_t k : {1u, 3u, 10u, 60u, 600u, 1199u}) {
    const double s_k = model::wind::kaimal_psd(static_cast<double>(k) * df, sigma, length, v);
    EXPECT_NEAR(periodogram(u, k, s.segment_s) / (g2 * s_k), 1.0, 1e-8) << "k = " << k;
  }
  // Nothing at DC or the Nyquist frequency.
  EXPECT_LT(periodogram(u, 1200, s.segment_s), 1e-20);
}

TEST(Turbulence, ClassesScaleSigma) {
  for (const auto c : {TurbulenceClass::kA, TurbulenceClass::kB, TurbulenceClass::kC}) {
    TurbulenceSettings s;
    s.turbulence_class = c;
    TurbulentWind w(s, 3);
    w.advance(12.0, 0.0);
    double var = 0.0;
    for (const double x : segment(w)) var += x * x;
    var /= static_cast<double>(w.samples_per_segment());
    const double sigma = model::wind::ntm_sigma_mps(c, 12.0);
    EXPECT_NEAR(std::sqrt(var), sigma, 1e-9 * sigma);
  }
}

TEST(Turbulence, SameSeedSameSeriesOtherSeedOther) {
  TurbulenceSettings s;
  TurbulentWind a(s, 11), b(s, 11), c(s, 12);
  for (int row = 0; row < 3; ++row) {
    a.advance(8.0, 8.0);
    b.advance(8.0, 8.0);
    c.advance(8.0, 8.0);
    double differ = 0.0;
    for (std::size_t j = 0; j < a.samples_per_segment(); ++j) {
      ASSERT_EQ(a.wind_mps(j), b.wind_mps(j));  // bitwise
      differ = std::max(differ, std::abs(a.wind_mps(j) - c.wind_mps(j)));
    }
    EXPECT_GT(differ, 0.5);  // σ1 = 1.86 m/s: two independent rows differ by more
  }
}

TEST(Turbulence, RowBoundaryIsContinuousAndRowMeansStay) {
  // Without the cross-fade two independent rows would meet with a step of order √2·σ1;
  // with it the boundary step is no larger than the steps inside the rows.
  TurbulenceSettings s;
  TurbulentWind w(s, 5);
  const std::vector<double> means{6.0, 9.0, 7.5, 7.5};
  double last = std::nan("");
  double max_inner_step = 0.0;
  double max_boundary_step = 0.0;
  for (std::size_t i = 0; i + 1 < means.size(); ++i) {
    w.advance(means[i], means[i + 1]);
    const std::size_t n = w.samples_per_segment();
    if (!std::isnan(last))
      max_boundary_step = std::max(max_boundary_step, std::abs(w.wind_mps(0) - last));
    double sum = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
      sum += w.wind_mps(j);
      if (j > 0)
        max_inner_step = std::max(max_inner_step, std::abs(w.wind_mps(j) - w.wind_mps(j - 1)));
    }
    last = w.wind_mps(n - 1);
    // Symmetric 30 s windows move a row's mean by ≤ 0.25·(15/600)·|ΔV| from the means, plus
    // the fluctuation's share over 30 of 600 s (≲ 0.05·σ1 = 0.1 m/s).
    EXPECT_NEAR(sum / static_cast<double>(n), means[i], 0.15) << "row " << i;
  }
  EXPECT_GT(max_inner_step, 0.0);
  EXPECT_LE(max_boundary_step, max_inner_step);
}

TEST(Turbulence, DiscDistanceDensityIsADensityWithTheKnownMean) {
  // Disc line picking: ∫p = 1 and the mean distance is 128·R/(45π) = 0.9054·R.
  const double r = 41.0;
  const int n = 4000;
  const double h = 2.0 * r / n;
  double mass = 0.0, mean = 0.0;
  for (int i = 0; i <= n; ++i) {
    const double d = h * i;
    const double w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
    mass += w * model::wind::disc_distance_density(d, r);
    mean += w * d * model::wind::disc_distance_density(d, r);
  }
  EXPECT_NEAR(mass * h / 3.0, 1.0, 1e-6);
  EXPECT_NEAR(mean * h / 3.0 / r, 128.0 / (45.0 * std::numbers::pi), 1e-6);
}

TEST(Turbulence, RotorAdmittanceAgreesWithAMonteCarloDiscAverage) {
  // χ(f) = E[Coh(|x − y|, f)] over two points uniform on the disc: sampled directly here
  // (rejection sampling in the square), no distance density involved. 200 000 pairs give a
  // standard error ≤ 0.5/√200000 = 1.1e-3; the tolerance is 5e-3.
  const double r = 41.0, v = 6.75, lc = model::wind::kaimal_length_scale_m(80.0);
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(-r, r);
  auto point = [&] {
    for (;;) {
      const double x = u(rng), y = u(rng);
      if (x * x + y * y <= r * r) return std::pair{x, y};
    }
  };
  for (const double f : {0.0, 0.02, 0.1, 0.5}) {
    double sum = 0.0;
    const int pairs = 200000;
    std::mt19937_64 fresh(7);
    rng = fresh;
    for (int i = 0; i < pairs; ++i) {
      const auto [x1, y1] = point();
      const auto [x2, y2] = point();
      sum += model::wind::iec_coherence(std::hypot(x1 - x2, y1 - y2), f, v, lc);
    }
    EXPECT_NEAR(model::wind::rotor_admittance(f, v, r, lc), sum / pairs, 5e-3) << "f = " << f;
  }
  // Limits: less than 1 already at f = 0 (IEC's 0.12·d/L_c term), falling with f.
  EXPECT_LT(model::wind::rotor_admittance(0.0, v, r, lc), 1.0);
  EXPECT_GT(model::wind::rotor_admittance(0.0, v, r, lc), 0.8);
  EXPECT_LT(model::wind::rotor_admittance(1.0, v, r, lc), 0.05);
}

TEST(Turbulence, RotorEffectiveWindKeepsThePointGain) {
  // Variance of the disc-averaged row = σ1²·Σ S·χ / Σ S (the point wind's gain kept).
  TurbulenceSettings s;
  s.rotor_radius_m = 41.0;
  TurbulentWind w(s, 9);
  const double v = 6.75;
  w.advance(v, 0.0);
  double var = 0.0;
  for (const double x : segment(w)) var += x * x;
  var /= static_cast<double>(w.samples_per_segment());
  const double sigma = model::wind::ntm_sigma_mps(TurbulenceClass::kA, v);
  const double length = model::wind::kaimal_length_scale_m(s.hub_height_m);
  const double df = 1.0 / s.segment_s;
  double plain = 0.0, averaged = 0.0;
  for (std::size_t k = 1; k < w.samples_per_segment() / 2; ++k) {
    const double f = static_cast<double>(k) * df;
    const double sk = model::wind::kaimal_psd(f, sigma, length, v);
    plain += sk;
    averaged += sk * model::wind::rotor_admittance(f, v, s.rotor_radius_m, length);
  }
  EXPECT_NEAR(var / (sigma * sigma * averaged / plain), 1.0, 1e-10);
  EXPECT_LT(averaged / plain, 0.9);
}

TEST(Turbulence, BadSettingsNamed) {
  const char* what = nullptr;
  TurbulenceSettings s;
  s.sample_period_s = 0.0;
  EXPECT_FALSE(model::wind::valid_turbulence_settings(s, &what));
  EXPECT_NE(std::string(what).find("sample period"), std::string::npos);
  s = TurbulenceSettings{};
  s.sample_period_s = 0.7;  // 600/0.7 is not whole
  EXPECT_FALSE(model::wind::valid_turbulence_settings(s, &what));
  EXPECT_NE(std::string(what).find("even whole number"), std::string::npos);
  s = TurbulenceSettings{};
  s.hub_height_m = -1.0;
  EXPECT_FALSE(model::wind::valid_turbulence_settings(s, &what));
  EXPECT_NE(std::string(what).find("hub height"), std::string::npos);
  EXPECT_TRUE(model::wind::valid_turbulence_settings(TurbulenceSettings{}, &what));
}

}  // namespace
