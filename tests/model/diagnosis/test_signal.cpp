// The diagnosis toolkit's signal processing against signals whose answer is known by
// hand: sines, amplitude-modulated carriers, impulse trains, Gaussian noise.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "model/diagnosis/fft.hpp"
#include "model/diagnosis/signal.hpp"

namespace {

namespace md = model::diagnosis;
constexpr double kPi = std::numbers::pi;

TEST(FftSizes, AreTheNearest235SmoothNumbers) {
  EXPECT_EQ(md::fft_size_at_least(7), 8u);
  EXPECT_EQ(md::fft_size_at_least(11), 12u);
  EXPECT_EQ(md::fft_size_at_least(97), 100u);
  EXPECT_EQ(md::fft_size_at_most(97), 96u);
  EXPECT_EQ(md::fft_size_at_most(429), 405u);
  EXPECT_EQ(md::fft_size_at_least(1), 1u);
}

TEST(Fft, InverseOfForwardIsTheIdentityAndACosineLandsOnItsBins) {
  // Arrange: N = 360 (2³·3²·5), x = 3·cos(2π·7n/N) + noise-free ramp.
  const std::size_t n = 360;
  md::Fft fft(n);
  std::vector<md::Complex> x(n), spec(n), back(n);
  for (std::size_t i = 0; i < n; ++i) x[i] = 3.0 * std::cos(2.0 * kPi * 7.0 * i / n);
  // Act
  fft.forward(x.data(), spec.data());
  fft.inverse(spec.data(), back.data());
  // Assert: a cosine of amplitude A puts A·N/2 on bins k and N−k, nothing elsewhere.
  EXPECT_NEAR(spec[7].real(), 3.0 * n / 2.0, 1e-9);
  EXPECT_NEAR(spec[n - 7].real(), 3.0 * n / 2.0, 1e-9);
  EXPECT_NEAR(std::abs(spec[8]), 0.0, 1e-9);
  for (std::size_t i = 0; i < n; ++i) EXPECT_NEAR(back[i].real(), x[i].real(), 1e-12);
}

TEST(Statistics, OfASineAndOfGaussianNoiseMatchTheirClosedForms) {
  // A sine: RMS A/√2, crest factor √2, kurtosis 3/2. Gaussian noise: kurtosis 3.
  const std::size_t n = 100000;
  std::vector<double> s(n), g(n);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> gauss(0.0, 2.0);
  for (std::size_t i = 0; i < n; ++i) {
    s[i] = 5.0 + 2.0 * std::sin(2.0 * kPi * 50.0 * i / n);  // 50 whole periods
    g[i] = gauss(rng);
  }
  const md::WaveformStatistics a = md::statistics(s.data(), n);
  EXPECT_NEAR(a.mean, 5.0, 1e-9);
  EXPECT_NEAR(a.rms, 2.0 / std::sqrt(2.0), 1e-9);
  EXPECT_NEAR(a.crest_factor, std::sqrt(2.0), 1e-6);
  EXPECT_NEAR(a.kurtosis, 1.5, 1e-6);
  const md::WaveformStatistics b = md::statistics(g.data(), n);
  EXPECT_NEAR(b.rms, 2.0, 0.02);
  EXPECT_NEAR(b.kurtosis, 3.0, 0.06);  // standard error √(24/n) = 0.015
}

TEST(HannSpectrum, ReadsASineOnALineAndBetweenLinesByLobeEnergy) {
  // N = 1000 (2³·5³), a sine of amplitude 1.7 at line 100 and one of 0.6 at line 230.5.
  const std::size_t n = 1000;
  md::Fft fft(n);
  std::vector<double> x(n), a;
  for (std::size_t i = 0; i < n; ++i)
    x[i] = 1.7 * std::sin(2.0 * kPi * 100.0 * i / n + 0.4) +
           0.6 * std::sin(2.0 * kPi * 230.5 * i / n + 1.1);
  md::hann_amplitude_spectrum(x.data(), n, fft, a);
  EXPECT_NEAR(a[100], 1.7, 1e-6);  // the other sine's far Hann sidelobes add ~5e-8
  EXPECT_NEAR(a[99], 0.85, 1e-6);
  // Between lines the peak loses 1.42 dB (Hann scalloping) but the lobe energy does not.
  EXPECT_LT(a[230], 0.6 * 0.86);
  EXPECT_NEAR(md::lobe_amplitude(a, 230.5, 3), 0.6, 0.006);
}

TEST(Envelope, OfAnAmplitudeModulatedCarrierIsTheModulation) {
  // x = (1 + 0.5·cos(2π·30t))·cos(2π·2000t), fs = 16384 Hz: the analytic signal of the
  // band 1800–2200 Hz has modulus 1 + 0.5·cos(2π·30t).
  const double fs = 16384.0;
  const std::size_t n = 16384;
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = i / fs;
    x[i] = (1.0 + 0.5 * std::cos(2.0 * kPi * 30.0 * t)) * std::cos(2.0 * kPi * 2000.0 * t);
  }
  const auto a = md::band_analytic(x.data(), n, fs, 1800.0, 2200.0);
  for (std::size_t i = 100; i < n - 100; i += 37) {
    const double t = i / fs;
    EXPECT_NEAR(std::abs(a[i]), 1.0 + 0.5 * std::cos(2.0 * kPi * 30.0 * t), 1e-6);
  }
}

TEST(CepstralPrewhitening, FlattensTheMagnitudeSpectrumAndKeepsThePhase) {
  // Lines of very different amplitude plus noise; after CPW every line has |X| = 1
  // (the real cepstrum zeroed except at quefrency 0) and the phase is the tapered input's.
  const std::size_t n = 4096;
  std::vector<double> x(n);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> gauss(0.0, 0.01);
  for (std::size_t i = 0; i < n; ++i)
    x[i] = 100.0 * std::sin(2.0 * kPi * 37.0 * i / n) + 0.1 * std::sin(2.0 * kPi * 501.0 * i / n) +
           gauss(rng);
  const auto w = md::cepstral_prewhiten(x.data(), n);
  md::Fft fft(n);
  std::vector<md::Complex> in(n), ws(n), xs(n);
  for (std::size_t i = 0; i < n; ++i) in[i] = w[i];
  fft.forward(in.data(), ws.data());
  // The phase is that of x tapered at its ends as cepstral_prewhiten does (Tukey).
  const auto edge = static_cast<std::size_t>(md::kCpwTaper * n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t from_end = std::min(i, n - 1 - i);
    const double taper = from_end < edge ? 0.5 * (1.0 - std::cos(kPi * from_end / edge)) : 1.0;
    in[i] = x[i] * taper;
  }
  fft.forward(in.data(), xs.data());
  for (std::size_t k = 1; k < n / 2; k += 13) {
    EXPECT_NEAR(std::abs(ws[k]), 1.0, 1e-9) << k;
    EXPECT_NEAR(std::remainder(std::arg(ws[k]) - std::arg(xs[k]), 2.0 * kPi), 0.0, 1e-6) << k;
  }
}

TEST(Cepstrum, OfAPeriodicImpulseTrainPeaksAtItsPeriod) {
  // Decaying bursts every 125 samples: a harmonic family spaced n/125 lines, whose
  // rahmonics sit at quefrency 125, 250, ...
  const std::size_t n = 8000;
  std::vector<double> x(n, 0.0);
  std::mt19937_64 rng(1);
  std::normal_distribution<double> gauss(0.0, 0.02);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t since = i % 125;
    x[i] = std::exp(-0.08 * since) * std::sin(2.0 * kPi * 0.21 * since) + gauss(rng);
  }
  const auto c = md::real_cepstrum(x.data(), n);
  std::size_t best = 20;
  for (std::size_t q = 20; q < 200; ++q)
    if (c[q] > c[best]) best = q;
  EXPECT_EQ(best, 125u);
}

TEST(Kurtogram, FindsTheResonanceThatRepeatedImpactsExcite) {
  // Gaussian noise plus impacts every 25 ms ringing a 3.5 kHz resonance (damping 2 %,
  // decay time τ = 1/(ζω) = 2.3 ms), fs = 20 kHz; the impacts carry about a tenth of the
  // energy of the noise. Alone, the ringing's envelope e^(−t/τ) repeated every T has
  // SK = T/τ − 2 ≈ 9; the kurtogram's best band contains 3.5 kHz and keeps most of that.
  const double fs = 20000.0;
  const std::size_t n = 65536;
  std::vector<double> x(n), noise_only(n);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double wn = 2.0 * kPi * 3500.0, zeta = 0.02;
  for (std::size_t i = 0; i < n; ++i) {
    const double t = i / fs;
    const double since = std::fmod(t, 0.025);
    noise_only[i] = gauss(rng);
    x[i] = noise_only[i] + 2.2 * std::exp(-zeta * wn * since) * std::sin(wn * since);
  }
  md::KurtogramConfig cfg;
  cfg.max_level = 6;
  const md::Kurtogram k = md::kurtogram(x.data(), n, fs, cfg);
  EXPECT_LE(k.best.f_lo_hz, 3500.0);
  EXPECT_GE(k.best.f_hi_hz, 3500.0);
  EXPECT_GT(k.best.kurtosis, 2.0);
  const md::Kurtogram k0 = md::kurtogram(noise_only.data(), n, fs, cfg);
  EXPECT_LT(k0.best.kurtosis, 0.5);  // Gaussian: 0 ± √(4/decimated samples) per band
  // A steady sine alone in its band reads −1.
  std::vector<double> s(n);
  for (std::size_t i = 0; i < n; ++i) s[i] = std::sin(2.0 * kPi * 1234.0 * i / fs);
  const md::Kurtogram ks = md::kurtogram(s.data(), n, fs, cfg);
  bool found = false;
  for (const auto& b : ks.bands) {
    if (b.level == 2.0 && b.f_lo_hz <= 1234.0 && b.f_hi_hz > 1234.0) {
      EXPECT_NEAR(b.kurtosis, -1.0, 0.02);
      found = true;
    }
  }
  EXPECT_TRUE(found);
}

TEST(Lowpass, RemovesWhatLiesAboveTheCutoffAndKeepsWhatLiesBelow) {
  const double fs = 1000.0;
  const std::size_t n = 1000;
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i)
    x[i] = std::sin(2.0 * kPi * 50.0 * i / fs) + std::sin(2.0 * kPi * 300.0 * i / fs);
  const auto y = md::lowpass(x.data(), n, fs, 100.0);
  for (std::size_t i = 0; i < n; i += 17)
    EXPECT_NEAR(y[i], std::sin(2.0 * kPi * 50.0 * i / fs), 1e-9);
}

}  // namespace
