// Locate and name on waveforms built by hand: a "simulated" gearbox tone set and a
// "recording" of the same tones plus one effect's lines, noise and a drifting speed.
// The expected answer follows from how the recording was built.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "model/diagnosis/analysis.hpp"
#include "model/diagnosis/locate.hpp"
#include "model/diagnosis/signatures.hpp"

namespace {

namespace md = model::diagnosis;
constexpr double kPi = std::numbers::pi;
constexpr double kFs = 25600.0;
constexpr double kHss = 14.3032;  // paper point

struct Drift {
  double f0 = kHss, d = 0.015, period = 23.0;
  double theta(double t) const {
    const double w = 2.0 * kPi / period;
    return f0 * (t - d / w * (std::cos(w * t) - 1.0));
  }
  double hz(double t) const { return f0 * (1.0 + d * std::sin(2.0 * kPi * t / period)); }
};

std::vector<double> pulses(const Drift& s, double duration) {
  std::vector<double> p;
  double t = 0.0;
  for (int k = 0;; ++k) {
    for (int it = 0; it < 30; ++it) t -= (s.theta(t) - k) / s.hz(t);
    if (t > duration) break;
    p.push_back(t);
    t += 1.0 / s.f0;
  }
  return p;
}

// The healthy gearbox: hs mesh (order 26) and intermediate mesh (order 5.1029) with harmonics.
// Intermediate mesh: 92 teeth on the sun shaft, 92·f_sun = 92·(21/92)(26/107)·f_hss.
constexpr double kImMesh = 21.0 * 26.0 / 107.0;
double healthy(double th) {
  return 1.0 * std::cos(2 * kPi * 26.0 * th) + 0.4 * std::cos(2 * kPi * 52.0 * th + 0.5) +
         0.15 * std::cos(2 * kPi * 78.0 * th + 1.0) + 0.6 * std::cos(2 * kPi * kImMesh * th) +
         0.2 * std::cos(2 * kPi * 2 * kImMesh * th + 0.2);
}

struct Case {
  std::vector<double> rec, sim;
  md::AngleMap rec_map, sim_map;
};

template <typename Effect, typename SimExtra>
Case make_case2(Effect&& effect, SimExtra&& sim_extra, double duration = 10.0, unsigned seed = 1) {
  Case c;
  const Drift s;
  const auto n = static_cast<std::size_t>(duration * kFs);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 0.05);
  c.rec.resize(n);
  c.sim.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / kFs;
    const double th = s.theta(t);
    c.rec[i] = healthy(th) + effect(t, th) + gauss(rng);
    c.sim[i] = healthy(kHss * t) + sim_extra(kHss * t);
  }
  c.rec_map = md::AngleMap::from_pulses(pulses(s, duration));
  c.sim_map = md::AngleMap::constant(kHss);
  return c;
}

template <typename Effect>
Case make_case(Effect&& effect, double duration = 10.0, unsigned seed = 1) {
  return make_case2(
      effect, [](double) { return 0.0; }, duration, seed);
}

struct Analysed {
  md::ChannelAnalysis rec, sim;
  md::LocateResult result;
  std::vector<md::ChannelPair> pairs;
};

void analyse(const Case& c, const md::Catalogue& cat, Analysed& a) {
  md::AnalysisConfig cfg;
  cfg.band_max_hz = 12000.0;
  const double env = md::envelope_max_order(cat);
  md::AnalysisWindow w{1.0, 135};
  ASSERT_TRUE(md::analyse_channel(c.rec.data(), c.rec.size(), kFs, c.rec_map, w, cat, cfg, env,
                                  nullptr, a.rec));
  ASSERT_TRUE(md::analyse_channel(c.sim.data(), c.sim.size(), kFs, c.sim_map, w, cat, cfg, env,
                                  &a.rec.band, a.sim));
  a.pairs = {{"point1", "b5", &a.rec, &a.sim}};
  a.result = md::locate(cat, a.pairs);
}

const md::Hypothesis& top(const md::Catalogue& cat, const md::LocateResult& r) {
  return cat.hypotheses[r.ranking.front().hypothesis];
}

TEST(Locate, NamesABroadHssSidebandFamilyAroundTheHsMeshAsACrackOfG4) {
  const md::Catalogue cat = md::build_catalogue(model::paper_2mw(), {"b5"});
  // Impulsive once-per-hss-revolution modulation of the mesh: sidebands k = 1..5 of
  // nearly equal strength around every mesh harmonic.
  const Case c = make_case([](double, double th) {
    double v = 0.0;
    for (int h = 1; h <= 3; ++h)
      for (int k = 1; k <= 5; ++k)
        v += 0.02 / h *
             (std::cos(2 * kPi * (26.0 * h + k) * th) + std::cos(2 * kPi * (26.0 * h - k) * th));
    return v;
  });
  Analysed a;
  analyse(c, cat, a);
  ASSERT_FALSE(a.result.ranking.empty());
  EXPECT_EQ(md::effect_id(top(cat, a.result).effect), std::string("tooth_crack"));
  EXPECT_EQ(top(cat, a.result).location, "g4");
  // The strongest spectrum feature is that family, in the band around the mesh harmonics.
  const md::ResidualFeature* first = nullptr;
  for (const auto& f : a.result.features)
    if (f.domain == md::FeatureDomain::kSpectrum && (!first || f.share > first->share)) first = &f;
  ASSERT_NE(first, nullptr);
  EXPECT_EQ(md::describe_feature(cat, *first, kHss, a.pairs),
            "sidebands of the high-speed mesh spaced at the hss speed (14.30 Hz)");
  EXPECT_GT(first->share, 0.9);
}

TEST(Locate, NamesFirstSidebandsAndA1xLineAsEccentricityOfG4) {
  const md::Catalogue cat = md::build_catalogue(model::paper_2mw(), {"b5"});
  const Case c = make_case([](double, double th) {
    double v = 0.03 * std::cos(2 * kPi * th);
    for (int h = 1; h <= 3; ++h)
      v += 0.03 / h *
           (std::cos(2 * kPi * (26.0 * h + 1) * th) + std::cos(2 * kPi * (26.0 * h - 1) * th));
    return v;
  });
  Analysed a;
  analyse(c, cat, a);
  ASSERT_FALSE(a.result.ranking.empty());
  EXPECT_EQ(md::effect_id(top(cat, a.result).effect), std::string("gear_eccentricity"));
  EXPECT_EQ(top(cat, a.result).location, "g4");
}

TEST(Locate, NamesA2xLineAsMisalignmentAndA1xLineAsUnbalanceOfTheIms) {
  const md::Catalogue cat = md::build_catalogue(model::paper_2mw(), {"b5"});
  const double ims = 26.0 / 107.0;
  Analysed a2;
  analyse(make_case([&](double, double th) {
            return 0.05 * std::cos(2 * kPi * 2 * ims * th) + 0.02 * std::cos(2 * kPi * ims * th);
          }),
          cat, a2);
  ASSERT_FALSE(a2.result.ranking.empty());
  EXPECT_EQ(md::effect_id(top(cat, a2.result).effect), std::string("shaft_misalignment"));
  EXPECT_EQ(top(cat, a2.result).location, "ims");
  Analysed a1;
  analyse(make_case([&](double, double th) { return 0.05 * std::cos(2 * kPi * ims * th); }), cat,
          a1);
  ASSERT_FALSE(a1.result.ranking.empty());
  EXPECT_EQ(md::effect_id(top(cat, a1.result).effect), std::string("shaft_unbalance"));
  EXPECT_EQ(top(cat, a1.result).location, "ims");
}

TEST(Locate, FindsOuterRaceImpactsOfB5InTheEnvelopeOfTheBandWhereTheyRing) {
  // Impacts at b5's BPFO (6.5066 hss orders) with 1 % slip ringing a 6 kHz resonance,
  // too weak to show in the spectrum's lines.
  const md::Catalogue cat = md::build_catalogue(model::paper_2mw(), {"b5"});
  const double bpfo = 93.066 / kHss * 0.99;
  const double wn = 2 * kPi * 6000.0;
  const Case c = make_case([&](double t, double th) {
    const double since_rev =
        std::fmod(th * bpfo, 1.0) / (bpfo * kHss);  // [s] since the last impact
    (void)t;
    return 0.25 * std::exp(-0.03 * wn * since_rev) * std::sin(wn * since_rev);
  });
  Analysed a;
  analyse(c, cat, a);
  ASSERT_FALSE(a.result.ranking.empty());
  EXPECT_EQ(md::effect_id(top(cat, a.result).effect), std::string("bearing_outer_race_defect"));
  EXPECT_EQ(top(cat, a.result).location, "b5");
  EXPECT_LE(a.rec.band.f_lo_hz, 6000.0);
  EXPECT_GE(a.rec.band.f_hi_hz, 6000.0);
}

TEST(Locate, FindsALongImpactTrainOfB5InTheSpectrumWhereItRingsNothing) {
  // The same defect at 1.5 % slip, each impact a 4 ms half sine (a wide defect crossed
  // slowly) driving no resonance: its energy lies in the first BPFO harmonics themselves
  // (below 1.5/τ), nothing rings above them, and prewhitening levels those lines with the
  // noise. Read in the waveform's spectrum, off the gears' lines, it is the outer race of b5.
  const md::Catalogue cat = md::build_catalogue(model::paper_2mw(), {"b5"});
  const double bpfo = 93.066 / kHss * 0.985;
  const double tau = 0.004;
  const Case c = make_case([&](double, double th) {
    const double since = std::fmod(th * bpfo, 1.0) / (bpfo * kHss);  // [s] since the last impact
    return since < tau ? 0.2 * std::sin(kPi * since / tau) : 0.0;
  });
  Analysed a;
  analyse(c, cat, a);
  ASSERT_FALSE(a.result.ranking.empty());
  const md::Hypothesis& h = top(cat, a.result);
  EXPECT_EQ(md::effect_id(h.effect), std::string("bearing_outer_race_defect"));
  EXPECT_EQ(h.location, "b5");
  EXPECT_EQ(h.domain, md::Domain::kSpectrum);
  // Nothing impulsive for the envelope to read: the envelope reading of b5 does not rank.
  for (const auto& s : a.result.ranking) {
    const md::Hypothesis& g = cat.hypotheses[s.hypothesis];
    if (g.domain == md::Domain::kEnvelope && g.location == "b5") {
      EXPECT_LT(s.score, a.result.ranking.front().score);
    }
  }
}

TEST(Locate, TakesNoPlanetaryMeshCombInTheEnvelopeForABearingDefect) {
  // A healthy gearbox's envelope carries every harmonic of each mesh: here a 6 kHz ring
  // excited once per planetary-mesh period (99·f_carrier, 0.9609 hss orders), which the
  // simulation lacks. Its comb teeth lie within ±2 % slip of bearing lines (the 10th at
  // 9.61 orders, b5's BPFI at 9.49), but they are synchronous with a mesh: no bearing defect.
  const md::Catalogue cat = md::build_catalogue(model::paper_2mw(), {"b5"});
  const double pm = 99.0 / ((1.0 + 99.0 / 21.0) * (92.0 / 21.0) * (107.0 / 26.0));
  const double wn = 2 * kPi * 6000.0;
  const Case c = make_case([&](double, double th) {
    const double since = std::fmod(th * pm, 1.0) / (pm * kHss);  // [s] since the last mesh pulse
    return 0.25 * std::exp(-0.03 * wn * since) * std::sin(wn * since);
  });
  Analysed a;
  analyse(c, cat, a);
  for (const auto& s : a.result.ranking) {
    const md::Effect e = cat.hypotheses[s.hypothesis].effect;
    EXPECT_FALSE(e == md::Effect::kBearingOuterRaceDefect ||
                 e == md::Effect::kBearingInnerRaceDefect || e == md::Effect::kBearingBallDefect)
        << md::effect_id(e) << " @ " << cat.hypotheses[s.hypothesis].location << " score "
        << s.score;
  }
}

TEST(Locate, FindsNothingWhenTheRecordingIsTheSimulationPlusNoise) {
  const md::Catalogue cat = md::build_catalogue(model::paper_2mw(), {"b5"});
  Analysed a;
  analyse(make_case([](double, double) { return 0.0; }), cat, a);
  for (const auto& s : a.result.ranking)
    EXPECT_LT(s.score, 0.05) << md::effect_id(cat.hypotheses[s.hypothesis].effect);
}

}  // namespace

namespace {

// A comb of lines: every hss harmonic 1..120 with a slowly varying amplitude.
double comb(double th, const std::vector<double>& gain) {
  double v = 0.0;
  for (int k = 1; k <= 120; ++k)
    v += gain[k] * 0.05 / std::sqrt(k) * std::cos(2 * kPi * k * th + 0.37 * k * k);
  return v;
}

TEST(Locate, FitsAResonanceWhenEveryLineOfABandIsAmplifiedAlongOneTransmissibilityCurve) {
  const md::Catalogue cat = md::build_catalogue(model::paper_2mw(), {"b5"});
  // The recording: every line × |H(f)| of a 600 Hz resonator with 3 % damping.
  std::vector<double> ones(121, 1.0), h(121, 1.0);
  for (int k = 1; k <= 120; ++k) {
    const double r = k * kHss / 600.0, z = 0.03;
    h[k] = std::sqrt((1 + 4 * z * z * r * r) / ((1 - r * r) * (1 - r * r) + 4 * z * z * r * r));
  }
  const Case c = make_case2([&](double, double th) { return comb(th, h); },
                            [&](double th) { return comb(th, ones); });
  Analysed a;
  analyse(c, cat, a);
  const md::ResidualFeature* band = nullptr;
  for (const auto& f : a.result.features)
    if (f.domain == md::FeatureDomain::kBand) band = &f;
  ASSERT_NE(band, nullptr);
  EXPECT_NEAR(band->resonance_hz, 600.0, 30.0);
  ASSERT_FALSE(a.result.ranking.empty());
  EXPECT_EQ(md::effect_id(top(cat, a.result).effect), std::string("housing_resonance"));
}

TEST(Locate, FindsNoResonanceInAMisfitThatScattersFromLineToLine) {
  // A foreign gearbox's lines: each line's gain drawn at random (±10 dB), no common curve.
  const md::Catalogue cat = md::build_catalogue(model::paper_2mw(), {"b5"});
  std::vector<double> ones(121, 1.0), g(121, 1.0);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  for (int k = 1; k <= 120; ++k) g[k] = std::pow(10.0, u(rng) / 20.0);
  const Case c = make_case2([&](double, double th) { return comb(th, g); },
                            [&](double th) { return comb(th, ones); });
  Analysed a;
  analyse(c, cat, a);
  for (const auto& f : a.result.features)
    EXPECT_NE(f.domain, md::FeatureDomain::kBand) << f.resonance_hz;
}

}  // namespace
