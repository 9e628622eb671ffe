// Signal processing against analytic signals: sines of known amplitude,
// frequency and phase, whose spectra, RMS and order content are known by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <new>
#include <numbers>
#include <random>
#include <vector>

#include "model/dsp/mesh_features.hpp"
#include "model/dsp/order_tracking.hpp"
#include "model/dsp/spectrum.hpp"

// GCC 12 at -O2 (with ASan) inlines the replaced operator delete below into
// gtest's code and then mistakes free() on operator new's malloc() for a
// mismatch; both are ours and match.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
// Counting allocator for the no-allocation test (test binary only).
namespace {
std::size_t g_allocations = 0;
}
void* operator new(std::size_t size) {
  ++g_allocations;
  if (void* p = std::malloc(size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace {

using model::dsp::DspStatus;
constexpr double kPi = std::numbers::pi;

std::vector<double> sine(std::size_t n, double fs, double f, double a, double phase = 0.3,
                         double offset = 0.0) {
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i)
    x[i] = offset + a * std::sin(2.0 * kPi * f * static_cast<double>(i) / fs + phase);
  return x;
}

TEST(SpectrumAnalyzer, ReadsTheAmplitudeOfASineCentredOnALine) {
  // Arrange: N = 1024, fs = 1024 Hz → 1 Hz lines; 50 Hz sine of amplitude 2.5 plus an offset of 7.
  model::dsp::SpectrumAnalyzer analyzer(1024);
  const auto x = sine(1024, 1024.0, 50.0, 2.5, 0.3, 7.0);
  std::vector<double> a(analyzer.lines());
  // Act
  analyzer.amplitude_spectrum(x.data(), a.data());
  // Assert: the Hann amplitude correction 2/Σw makes the centre line read A;
  // the neighbours of a Hann-windowed line read A/2; the mean is removed.
  EXPECT_NEAR(a[50], 2.5, 1e-12);
  EXPECT_NEAR(a[49], 1.25, 1e-12);
  EXPECT_NEAR(a[51], 1.25, 1e-12);
  EXPECT_NEAR(a[0], 0.0, 1e-12);
  EXPECT_NEAR(a[60], 0.0, 1e-12);
}

TEST(SpectrumAnalyzer, ToneAmplitudeIsExactOnALineAndWithinHalfAPercentBetweenLines) {
  model::dsp::SpectrumAnalyzer analyzer(4096);
  std::vector<double> a(analyzer.lines());
  for (const double offset_lines : {0.0, 0.25, 0.5}) {
    // Arrange: sine at line 300 + offset; the peak line alone would lose up to
    // 15 % (Hann scalloping, 1.42 dB) at half a line.
    const auto x = sine(4096, 4096.0, 300.0 + offset_lines, 1.7);
    // Act
    analyzer.amplitude_spectrum(x.data(), a.data());
    const double amp = analyzer.tone_amplitude(a.data(), 300.0 + offset_lines, 2);
    // Assert: Σ a_k² over the main lobe = 1.5·A² (Hann ENBW 1.5 lines).
    EXPECT_NEAR(amp, 1.7, 1.7 * 5e-3) << "offset " << offset_lines;
  }
}

TEST(Rms, OfASineOverWholePeriodsIsAmplitudeOverRootTwoAndIgnoresTheMean) {
  const auto x = sine(1000, 1000.0, 10.0, 3.0, 0.1, -4.0);
  EXPECT_NEAR(model::dsp::rms(x.data(), x.size()), 3.0 / std::sqrt(2.0), 1e-12);
}

// Hand sums: measured lines 0..4 = {9, 3, 4, 0, 2} (line 0, the mean, never counted), simulated
// {7, 3, 1} (lines 3, 4 missing: 0). Up to line 4: miss = 0² + 3² + 0² + 2² = 13, total = 9 +
// 16 + 0 + 4 = 29. Up to line 2: 9 and 25. A last line beyond the measured spectrum stops at it.
TEST(UnexplainedEnergy, SumsTheMissAndTheMeasuredEnergyFromLineOneAndAddsChannels) {
  const std::vector<double> m{9.0, 3.0, 4.0, 0.0, 2.0};
  const std::vector<double> s{7.0, 3.0, 1.0};
  double miss = 0.0, total = 0.0;
  model::dsp::add_unexplained_energy(m.data(), m.size(), s.data(), s.size(), 4, miss, total);
  EXPECT_DOUBLE_EQ(miss, 13.0);
  EXPECT_DOUBLE_EQ(total, 29.0);
  model::dsp::add_unexplained_energy(m.data(), m.size(), s.data(), s.size(), 2, miss, total);
  EXPECT_DOUBLE_EQ(miss, 13.0 + 9.0);
  EXPECT_DOUBLE_EQ(total, 29.0 + 25.0);
  double miss2 = 0.0, total2 = 0.0;
  model::dsp::add_unexplained_energy(m.data(), m.size(), s.data(), s.size(), 100, miss2, total2);
  EXPECT_DOUBLE_EQ(miss2, 13.0);
  EXPECT_DOUBLE_EQ(total2, 29.0);
}

TEST(CheckWaveform, RejectsFlatClippedAndNonFiniteChannelsAndAcceptsANoisySine) {
  auto clean = sine(20000, 25600.0, 372.0, 1.0);
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 0.05);
  for (double& v : clean) v += noise(rng);
  EXPECT_EQ(model::dsp::check_waveform(clean.data(), clean.size(), 1e-9), DspStatus::kOk);

  std::vector<double> flat(20000, 0.25);
  EXPECT_EQ(model::dsp::check_waveform(flat.data(), flat.size(), 1e-9), DspStatus::kFlat);

  auto clipped = sine(20000, 25600.0, 372.0, 1.0);
  for (double& v : clipped)
    v = std::clamp(v, -0.8, 0.8);  // amplifier saturating at 80 % of the peak
  EXPECT_EQ(model::dsp::check_waveform(clipped.data(), clipped.size(), 1e-9), DspStatus::kClipped);

  auto broken = sine(20000, 25600.0, 372.0, 1.0);
  broken[777] = std::nan("");
  EXPECT_EQ(model::dsp::check_waveform(broken.data(), broken.size(), 1e-9), DspStatus::kNonFinite);
}

// A shaft whose speed ramps linearly from f0 to f1 over the record: angle
// θ(t) = f0·t + (f1 − f0)·t²/(2T) [rev]; a tacho pulse at every whole θ.
struct Ramp {
  double f0_hz, f1_hz, duration_s;
  double angle_rev(double t) const {
    return f0_hz * t + (f1_hz - f0_hz) * t * t / (2.0 * duration_s);
  }
  double time_of_rev(double rev) const {  // inverse of angle_rev
    const double a = (f1_hz - f0_hz) / (2.0 * duration_s);
    return (-f0_hz + std::sqrt(f0_hz * f0_hz + 4.0 * a * rev)) / (2.0 * a);
  }
};

TEST(OrderTracker, DetectsTachoPulsesWithinOneSampleOfTheirTrueTimes) {
  // Arrange: 5 ms pulses of 5 V at each revolution of a ramping hss.
  const double fs = 25600.0;
  const Ramp ramp{14.0, 14.6, 5.0};
  std::vector<double> tacho(static_cast<std::size_t>(fs * ramp.duration_s));
  for (std::size_t i = 0; i < tacho.size(); ++i) {
    const double t = static_cast<double>(i) / fs;
    const double frac = ramp.angle_rev(t) - std::floor(ramp.angle_rev(t));
    tacho[i] = (frac > 0.0 && frac < 0.07) ? 5.0 : 0.0;
  }
  model::dsp::OrderTracker tracker(256, 8, 1000);
  // Act
  const std::size_t pulses = tracker.detect_pulses(tacho.data(), tacho.size(), fs);
  // Assert: one pulse per whole revolution (rev 0 rises between samples 0 and
  // 1); a step located by linear interpolation is within one sample of the edge.
  ASSERT_EQ(pulses, static_cast<std::size_t>(std::floor(ramp.angle_rev(ramp.duration_s))) + 1);
  for (std::size_t k = 0; k < pulses; ++k) {
    EXPECT_NEAR(tracker.pulse_times()[k], ramp.time_of_rev(static_cast<double>(k)), 1.0 / fs);
  }
}

model::dsp::FeatureConfig hss_mesh_config() {
  model::dsp::FeatureConfig c;
  c.samples_per_rev = 512;
  c.revolutions = 64;
  c.harmonics = 3;
  c.mesh_orders = {26.0, 0.0, 0.0, 0.0};  // high-speed mesh: z_g4 = 26 per hss revolution
  c.mesh_count = 1;
  return c;
}

TEST(FeatureExtractor,
     TachoOrderTrackingRecoversMeshHarmonicsOfADriftingShaftThatAFixedSpeedSmears) {
  // Arrange: hss ramping +4 % over 5 s (more than a recording's ±2 %), mesh
  // harmonics 26, 52, 78 orders with amplitudes 1.0, 0.5, 0.2 m/s².
  const double fs = 25600.0;
  const Ramp ramp{14.0, 14.56, 5.0};
  const std::size_t n = static_cast<std::size_t>(fs * ramp.duration_s);
  std::vector<double> x(n);
  const double amps[3] = {1.0, 0.5, 0.2};
  for (std::size_t i = 0; i < n; ++i) {
    const double theta = ramp.angle_rev(static_cast<double>(i) / fs);
    for (int h = 1; h <= 3; ++h)
      x[i] += amps[h - 1] * std::cos(2.0 * kPi * 26.0 * h * theta + 0.4 * h);
  }
  std::vector<double> pulses;
  for (int k = 1; ramp.time_of_rev(k) < ramp.duration_s; ++k) pulses.push_back(ramp.time_of_rev(k));
  model::dsp::FeatureExtractor tracked(hss_mesh_config());
  ASSERT_EQ(tracked.config_status(), DspStatus::kOk);
  model::dsp::PointFeatures with_tacho;
  model::dsp::PointFeatures fixed_speed;
  // Act
  const auto s1 = tracked.extract(x.data(), n, fs, {pulses.data(), pulses.size(), 0.0}, with_tacho);
  const auto s2 = tracked.extract(x.data(), n, fs, {nullptr, 0, 14.28}, fixed_speed);
  // Assert: order tracking keeps each harmonic on its line (1 % tolerance for
  // the linear-in-time angle between pulses); a fixed speed smears the 78th
  // order over ±1.5 orders (≈ 96 lines), far outside the ±2-line lobe.
  ASSERT_EQ(s1, DspStatus::kOk);
  ASSERT_EQ(s2, DspStatus::kOk);
  ASSERT_EQ(with_tacho.count, 3u);
  for (int h = 0; h < 3; ++h)
    EXPECT_NEAR(with_tacho.amplitude[h], amps[h], 0.01 * amps[h]) << "harmonic " << h + 1;
  EXPECT_LT(fixed_speed.amplitude[2], 0.5 * amps[2]);
  // RMS of a sum of sines: sqrt(Σ A²/2).
  EXPECT_NEAR(with_tacho.rms, std::sqrt((1.0 + 0.25 + 0.04) / 2.0), 2e-3);
}

TEST(FeatureExtractor, RefusesARecordingShorterThanTheRevolutionsTheResolutionNeeds) {
  // Arrange: 64 revolutions at 14.3 Hz need 4.5 s; give 2 s.
  model::dsp::FeatureExtractor fx(hss_mesh_config());
  const auto x = sine(51200, 25600.0, 371.88, 1.0);
  model::dsp::PointFeatures f;
  // Act / Assert
  EXPECT_EQ(fx.extract(x.data(), x.size(), 25600.0, {nullptr, 0, 14.303}, f), DspStatus::kTooShort);
  EXPECT_NEAR(fx.required_duration_s(14.303), 65.0 / 14.303, 1e-12);
}

TEST(FeatureExtractor, RejectsAResolutionThatCannotSeparateTwoMeshHarmonics) {
  // Arrange: orders 26 and 26.01 are 0.16 lines apart at 16 revolutions: their Hann kernels
  // are nearly the same vector over the fitted lines, so the fit cannot tell them apart.
  auto c = hss_mesh_config();
  c.revolutions = 16;
  c.mesh_orders = {26.0, 26.01, 0.0, 0.0};
  c.mesh_count = 2;
  c.harmonics = 1;
  // Act / Assert
  EXPECT_EQ(model::dsp::FeatureExtractor(c).config_status(), DspStatus::kTooShort);
}

TEST(FeatureExtractor, SeparatesTwoTonesInsideEachOthersMainLobe) {
  // Arrange: orders 26 and 26.09375 at 16 revolutions are 1.5 lines apart, inside each
  // other's Hann main lobe (±2 lines): the lobe-energy estimate would sum them. Fitted at
  // their known orders (variance inflation below 2: their kernels differ enough over the
  // fitted lines), noise-free amplitudes 1.0 and 0.4 come back up to the order tracker's
  // cubic interpolation (0.5 %).
  auto c = hss_mesh_config();
  c.revolutions = 16;
  c.mesh_orders = {26.0, 26.09375, 0.0, 0.0};
  c.mesh_count = 2;
  c.harmonics = 1;
  model::dsp::FeatureExtractor fx(c);
  ASSERT_EQ(fx.config_status(), DspStatus::kOk) << fx.variance_inflation(0);
  const double fs = 25600.0;
  const double shaft = 14.3;
  std::vector<double> x(static_cast<std::size_t>(fs * 1.5));
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double t = static_cast<double>(i) / fs;
    x[i] = std::cos(2 * kPi * 26.0 * shaft * t + 0.3) +
           0.4 * std::cos(2 * kPi * 26.09375 * shaft * t + 2.0);
  }
  model::dsp::PointFeatures f;
  // Act
  ASSERT_EQ(fx.extract(x.data(), x.size(), fs, {nullptr, 0, shaft}, f), DspStatus::kOk);
  // Assert
  EXPECT_LT(fx.variance_inflation(0), c.max_variance_inflation);
  EXPECT_NEAR(f.amplitude[0], 1.0, 0.005);
  EXPECT_NEAR(f.amplitude[1], 0.4, 0.005);
}

TEST(FeatureExtractor, AnUnbalanceLineAtHssOneTimesDoesNotBiasThePlanetaryMeshTone) {
  // Arrange: paper-2mw's planetary mesh sits at 0.961 hss orders, 2.5 lines below the hss
  // 1× line at 64 revolutions — inside its Hann main lobe (±2 lines), so the lobe-energy
  // estimate of 0.961 took in the 1× line. A planetary tone of 0.02 m/s² next to an
  // unbalance line of 0.5 m/s² (25×): with the hss declared a shaft the fit separates them;
  // the planetary amplitude comes back within 2 %, as without the unbalance line.
  auto c = hss_mesh_config();
  c.mesh_orders = {13.745 / 14.3032, 26.0, 0.0, 0.0};
  c.mesh_count = 2;
  c.harmonics = 1;
  c.shaft_orders = {1.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  c.shaft_count = 1;
  model::dsp::FeatureExtractor fx(c);
  ASSERT_EQ(fx.config_status(), DspStatus::kOk);
  const double fs = 25600.0;
  const double shaft = 14.3032;
  std::vector<double> with(static_cast<std::size_t>(fs * 5.0));
  std::vector<double> without(with.size());
  for (std::size_t i = 0; i < with.size(); ++i) {
    const double t = static_cast<double>(i) / fs;
    without[i] = 0.02 * std::cos(2 * kPi * 13.745 * t + 1.0) + std::cos(2 * kPi * 26 * shaft * t);
    with[i] = without[i] + 0.5 * std::cos(2 * kPi * shaft * t + 0.7);
  }
  model::dsp::PointFeatures f_with;
  model::dsp::PointFeatures f_without;
  // Act
  ASSERT_EQ(fx.extract(without.data(), without.size(), fs, {nullptr, 0, shaft}, f_without),
            DspStatus::kOk);
  ASSERT_EQ(fx.extract(with.data(), with.size(), fs, {nullptr, 0, shaft}, f_with), DspStatus::kOk);
  // Assert
  EXPECT_NEAR(f_without.amplitude[0], 0.02, 0.0004);
  EXPECT_NEAR(f_with.amplitude[0], 0.02, 0.0004);
  EXPECT_TRUE(f_with.separable[0]);
  // The lobe-energy estimate of the old extractor (±2 lines) reads the unbalance line in.
  const double lobe = model::dsp::SpectrumAnalyzer(c.samples_per_rev * c.revolutions)
                          .tone_amplitude(fx.order_spectrum(), 0.961 * 64, 2);
  EXPECT_GT(lobe, 0.1);
}

TEST(FeatureExtractor, AToneAKnownLineCoversIsFlaggedNotSeparable) {
  // Arrange: a shaft line 0.1 lines from the compared tone: no resolution separates them.
  auto c = hss_mesh_config();
  c.shaft_orders = {26.0 + 0.1 / 64.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  c.shaft_count = 1;
  c.shaft_harmonics = 1;
  model::dsp::FeatureExtractor fx(c);
  ASSERT_EQ(fx.config_status(), DspStatus::kOk);
  const auto x = sine(static_cast<std::size_t>(25600 * 5.0), 25600.0, 26.0 * 14.3, 1.0);
  model::dsp::PointFeatures f;
  // Act
  ASSERT_EQ(fx.extract(x.data(), x.size(), 25600.0, {nullptr, 0, 14.3}, f), DspStatus::kOk);
  // Assert
  EXPECT_GT(fx.variance_inflation(0), c.max_variance_inflation);
  EXPECT_FALSE(f.separable[0]);
  EXPECT_FALSE(f.resolved[0]);
}

TEST(EstimateShaftHzFromMesh,
     FindsTheTrueSpeedFromTheMeshLineWhenTheNominalSpeedIsThreePercentOff) {
  // Arrange: hss at 14.303 Hz, mesh 26·14.303 = 371.88 Hz; nominal 3 % low.
  const double fs = 25600.0;
  const auto x = sine(65536, fs, 26.0 * 14.303, 1.0);
  model::dsp::SpectrumAnalyzer analyzer(65536);
  std::vector<double> work(analyzer.lines());
  // Act
  const auto f = model::dsp::estimate_shaft_hz_from_mesh(x.data(), x.size(), fs, 14.303 * 0.97,
                                                         26.0, 0.05, analyzer, work.data());
  // Assert: the line spacing is 0.39 Hz at the mesh → 0.015 Hz at the shaft;
  // the centroid does better than one line.
  ASSERT_TRUE(f.has_value());
  EXPECT_NEAR(*f, 14.303, 0.39 / 26.0);
}

TEST(FeatureExtractor, MarksAToneBuriedInNoiseAsUnresolvedAndEstimatesTheNoiseFloor) {
  // Arrange: mesh order 26 at 1.0 m/s², its 2nd harmonic at 0.001 m/s², its 3rd
  // at 0.3 m/s², white noise σ = 0.2 m/s². The angle-domain block has
  // N = 512·64 = 32768 samples; with the Hann window (Σw² = 3N/8) a line of the raw
  // transform has E|X|² = σ²·3N/8, and the fitted amplitude 2|c| of an isolated tone,
  // c = Σ W*X / Σ|W|² with Σ|W|² = 3N²/8 over its lines, reads noise of RMS
  // 2σ·sqrt(3N/8)/sqrt(3N²/8) = 2σ/√N = 0.0022 m/s² (cubic interpolation lowers σ by up
  // to 20 %: expect 0.0015–0.003). The 2nd harmonic is below it, the 3rd ~130× above.
  const double fs = 25600.0;
  const std::size_t n = static_cast<std::size_t>(fs * 5.0);
  std::vector<double> x(n);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.2);
  for (std::size_t i = 0; i < n; ++i) {
    const double w = 2.0 * kPi * 26.0 * 14.3 * static_cast<double>(i) / fs;
    x[i] = std::sin(w) + 0.001 * std::sin(2 * w) + 0.3 * std::sin(3 * w) + noise(rng);
  }
  model::dsp::FeatureExtractor fx(hss_mesh_config());
  model::dsp::PointFeatures f;
  // Act
  ASSERT_EQ(fx.extract(x.data(), n, fs, {nullptr, 0, 14.3}, f), DspStatus::kOk);
  // Assert
  EXPECT_TRUE(f.resolved[0]);
  EXPECT_FALSE(f.resolved[1]);
  EXPECT_TRUE(f.resolved[2]);
  EXPECT_EQ(f.resolved_count(), 2u);
  EXPECT_NEAR(f.amplitude[2], 0.3, 0.03);
  EXPECT_GT(f.noise_floor[1], 0.0015);
  EXPECT_LT(f.noise_floor[1], 0.003);
}

TEST(FeatureExtractor, ExtractsWithoutAllocatingAfterConstruction) {
  const double fs = 25600.0;
  const auto x = sine(static_cast<std::size_t>(fs * 5.0), fs, 26.0 * 14.3, 1.0);
  model::dsp::FeatureExtractor fx(hss_mesh_config());
  model::dsp::PointFeatures f;
  // Warm-up once, then count.
  ASSERT_EQ(fx.extract(x.data(), x.size(), fs, {nullptr, 0, 14.3}, f), DspStatus::kOk);
  const std::size_t before = g_allocations;
  for (int k = 0; k < 3; ++k)
    ASSERT_EQ(fx.extract(x.data(), x.size(), fs, {nullptr, 0, 14.3}, f), DspStatus::kOk);
  EXPECT_EQ(g_allocations, before);
  EXPECT_NEAR(f.amplitude[0], 1.0, 0.01);
}

}  // namespace
