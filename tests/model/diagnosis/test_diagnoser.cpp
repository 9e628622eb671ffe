// The whole diagnosis on a gearbox whose vibration is known in closed form: a
// "tone gearbox" (every mesh of paper-2mw with three harmonics whose amplitudes depend
// log-linearly on the calibration parameters) and, switchable, a g4 tooth crack (a
// sideband family around the high-speed mesh whose strength is the crack's stiffness
// loss). The recording is the tone gearbox at drifted parameters, with or without the
// crack, a ±1.5 % speed drift and noise; the expected answer follows from how it was made.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "model/calibration/lumped_simulator.hpp"
#include "model/diagnosis/diagnoser.hpp"

namespace {

namespace md = model::diagnosis;
namespace mc = model::calibration;
constexpr double kPi = std::numbers::pi;

// Amplitude of mesh harmonic (stage s, harmonic h) at point p for parameters q.
double tone_amplitude(const model::DynamicsParameters& q, std::size_t s, int h, std::size_t p) {
  const double base = (s == 2 ? 1.0 : (s == 1 ? 0.5 : 0.2)) / h * (p == 0 ? 1.0 : 0.6);
  // Log-linear in the parameters, each harmonic its own mix, so the calibration can tell them
  // apart.
  const double g = std::pow(q.mesh_stiffness_scale[s], 0.8 + 0.3 * h) *
                   std::pow(q.bearing_stiffness_scale[s], p == 0 ? -0.6 : -0.3 * h) *
                   std::pow(q.rayleigh_zeta / 1e-5, -0.2 * h) *
                   std::pow(q.rayleigh_eta / 5.0, -0.05);
  return base * g;
}

struct ToneGearbox {
  std::array<double, 3> mesh_orders{};
  explicit ToneGearbox(const md::Catalogue& cat) {
    for (std::size_t s = 0; s < 3; ++s) mesh_orders[s] = cat.meshes[s].order;
  }
  // Point p as a function of the reference angle [rev]: mesh tones at parameters q, a g4
  // crack of severity c (hss-spaced sidebands k = 1..4 around the high-speed mesh), an hss
  // unbalance.
  struct Tone {
    double order, amplitude, phase;
  };
  std::vector<Tone> tones(const model::DynamicsParameters& q, double c, double unbalance,
                          std::size_t p) const {
    std::vector<Tone> t;
    for (std::size_t s = 0; s < 3; ++s)
      for (int h = 1; h <= 3; ++h)
        t.push_back({h * mesh_orders[s], tone_amplitude(q, s, h, p), 0.3 * h + s});
    if (c > 0.0) {
      for (int h = 1; h <= 3; ++h)
        for (int k = 1; k <= 4; ++k) {
          const double a = c * tone_amplitude(q, 2, h, p) * 0.8 / std::sqrt(static_cast<double>(k));
          t.push_back({h * 26.0 + k, a, 0.7 * k});
          t.push_back({h * 26.0 - k, a, -0.4 * k});
        }
    }
    if (unbalance > 0.0) t.push_back({1.0, unbalance, 0.1});
    return t;
  }
  static double value(const std::vector<Tone>& tones, double th) {
    double v = 0.0;
    for (const Tone& t : tones) v += t.amplitude * std::cos(2 * kPi * t.order * th + t.phase);
    return v;
  }
};

// Lines only a simulation has (a foreign gearbox's misfit, a term that spoils the spectrum):
// one always there, one proportional to the crack's severity, both at point 1.
struct SpuriousLines {
  double always = 0.0;     // [m/s²] at kAlwaysOrder
  double per_crack = 0.0;  // [m/s² per unit stiffness loss] at kCrackOrder
  static constexpr double kAlwaysOrder = 40.5, kCrackOrder = 45.5;
};

class ToneEffectSimulator : public md::EffectSimulator {
 public:
  explicit ToneEffectSimulator(const md::Catalogue& cat, SpuriousLines spurious = {})
      : box_(cat), ref_per_rotor_(cat.reference_per_rotor), spurious_(spurious) {}
  std::vector<md::EffectParameter> parameters(const md::Hypothesis& h) const override {
    if (h.effect == md::Effect::kToothCrack && h.location == "g4")
      return {{"stiffness_loss", 1e-3, 1.0, 0.05, true}};
    if (h.effect == md::Effect::kShaftUnbalance && h.location == "hss")
      return {{"force", 1e-4, 1.0, 0.01, true}};
    return {};
  }
  bool simulate(const model::DynamicsParameters& q, const std::vector<md::EffectSetting>& effects,
                const mc::OperatingPoint& op, double fs, double duration_s,
                std::array<mc::WaveformView, mc::kMeasurementPoints>& out) override {
    double crack = 0.0, unbalance = 0.0;
    for (const md::EffectSetting& e : effects) {
      if (e.hypothesis->effect == md::Effect::kToothCrack) crack = e.values[0];
      if (e.hypothesis->effect == md::Effect::kShaftUnbalance) unbalance = e.values[0];
    }
    const double f = op.rotor_speed_rpm / 60.0 * ref_per_rotor_;
    const auto n = static_cast<std::size_t>(duration_s * fs);
    for (std::size_t p = 0; p < mc::kMeasurementPoints; ++p) {
      wave_[p].resize(n);
      auto tones = box_.tones(q, crack, unbalance, p);
      if (p == 0 && spurious_.always > 0.0)
        tones.push_back({SpuriousLines::kAlwaysOrder, spurious_.always, 0.0});
      if (p == 0 && crack > 0.0 && spurious_.per_crack > 0.0)
        tones.push_back({SpuriousLines::kCrackOrder, spurious_.per_crack * crack, 0.0});
      // At a constant speed each tone is a phasor turned by a fixed angle per sample (the
      // same sum as ToneGearbox::value, without a cosine per tone and sample).
      std::fill(wave_[p].begin(), wave_[p].end(), 0.0);
      for (const ToneGearbox::Tone& t : tones) {
        const double step = 2 * kPi * t.order * f / fs;
        const double wc = std::cos(step), ws = std::sin(step);
        double c = t.amplitude * std::cos(t.phase), s = t.amplitude * std::sin(t.phase);
        for (std::size_t i = 0; i < n; ++i) {
          wave_[p][i] += c;
          const double c_next = c * wc - s * ws;
          s = c * ws + s * wc;
          c = c_next;
        }
      }
      out[p] = {wave_[p].data(), n, fs};
    }
    return true;
  }
  const std::string& error() const override { return error_; }

 private:
  ToneGearbox box_;
  double ref_per_rotor_;
  SpuriousLines spurious_;
  std::array<std::vector<double>, mc::kMeasurementPoints> wave_;
  std::string error_;
};

struct Recording {
  std::array<std::vector<double>, mc::kMeasurementPoints> points;
  double fs = 25600.0;
};

// The recording: truth parameters, a crack of `crack`, speed drifting ±1.5 % (no tacho), noise.
Recording record(const md::Catalogue& cat, const model::DynamicsParameters& truth, double crack,
                 double seconds, unsigned seed) {
  Recording r;
  const ToneGearbox box(cat);
  const double f0 = 8.33 / 60.0 * cat.reference_per_rotor, d = 0.015, period = 17.0;
  const auto n = static_cast<std::size_t>(seconds * r.fs);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 0.02);
  for (std::size_t p = 0; p < mc::kMeasurementPoints; ++p) {
    r.points[p].resize(n);
    const auto tones = box.tones(truth, crack, 0.0, p);
    for (std::size_t i = 0; i < n; ++i) {
      const double t = static_cast<double>(i) / r.fs;
      const double w = 2 * kPi / period;
      const double th = f0 * (t - d / w * (std::cos(w * t) - 1.0));
      r.points[p][i] = ToneGearbox::value(tones, th) + gauss(rng);
    }
  }
  return r;
}

model::DynamicsParameters drifted() {
  model::DynamicsParameters q = mc::with_nominal_damping(model::paper_2mw().dynamics);
  q.rayleigh_zeta *= 1.4;
  q.mesh_stiffness_scale = {0.9, 0.85, 0.8};
  q.bearing_stiffness_scale = {1.1, 1.2, 1.25};
  return q;
}

md::DiagnosisInput input_of(const Recording& r) {
  md::DiagnosisInput in;
  in.sample_rate_hz = r.fs;
  in.points = {r.points[0].data(), r.points[1].data()};
  in.samples = r.points[0].size();
  in.rotor_speed_rpm = 8.33;
  in.input_torque_nm = 361747.0;
  return in;
}

md::DiagnoserConfig config() {
  md::DiagnoserConfig c;
  c.calibration.trust_region.max_evaluations = 40;
  return c;
}

const model::Drivetrain& paper() {
  static const model::Drivetrain d = model::paper_2mw();
  return d;
}

// Starts `d` on the recording and steps it until it stops; the final step.
md::DiagnosisStep run_to_end(md::Diagnoser& d, const Recording& r) {
  d.start(input_of(r));
  md::DiagnosisStep st;
  while ((st = d.step()) == md::DiagnosisStep::kRunning) {
  }
  return st;
}

TEST(Diagnoser, NamesTheCrackOfG4FitsItsSeverityAndHalvesTheResidual) {
  md::RomEffectSimulator unused(paper(), 0.0);
  md::Diagnoser probe(paper(), unused);
  ToneEffectSimulator sim(probe.catalogue());
  md::Diagnoser d(paper(), sim, config());
  const Recording r = record(probe.catalogue(), drifted(), 0.08, 14.0, 1);
  ASSERT_EQ(run_to_end(d, r), md::DiagnosisStep::kFinished) << d.report().message;
  const md::DiagnosisReport& rep = d.report();
  EXPECT_EQ(rep.speed_source, "mesh line");
  ASSERT_EQ(rep.missing.size(), 1u);
  const md::CandidateResult& c = rep.candidates[rep.missing[0]];
  EXPECT_EQ(c.effect, md::Effect::kToothCrack);
  EXPECT_EQ(c.location, "g4");
  ASSERT_EQ(c.parameters.size(), 1u);
  EXPECT_NEAR(c.parameters[0].second / 0.08, 1.0, 0.2);
  EXPECT_GT(c.confidence, 0.5);
  EXPECT_LT(rep.residual_after, 0.5 * rep.residual_calibrated);
  // Published for other threads.
  md::DiagnosisSummary s;
  ASSERT_TRUE(d.read_result(s));
  EXPECT_TRUE(s.finished);
  ASSERT_EQ(s.reported, 1u);
  EXPECT_STREQ(s.effects[0].location.data(), "g4");
}

TEST(Diagnoser, ReportsNothingWhenOnlyTheParametersDrifted) {
  md::RomEffectSimulator unused(paper(), 0.0);
  md::Diagnoser probe(paper(), unused);
  ToneEffectSimulator sim(probe.catalogue());
  md::Diagnoser d(paper(), sim, config());
  const Recording r = record(probe.catalogue(), drifted(), 0.0, 14.0, 2);
  ASSERT_EQ(run_to_end(d, r), md::DiagnosisStep::kFinished) << d.report().message;
  EXPECT_TRUE(d.report().missing.empty());
  for (const md::CandidateResult& c : d.report().candidates)
    EXPECT_FALSE(c.accepted) << md::effect_id(c.effect);
}

// The guard (diagnoser.hpp, decide (c)) on a gearbox the calibration cannot fit: the
// simulation always carries a line the recording lacks, stronger than the whole recording,
// so the report's residual is clipped at 1 with and without any term. The crack's term
// explains its sidebands but also adds a line the recording lacks (30 m/s² per unit loss:
// 2.4 at the true 0.08, against recorded tones of at most ~1). Judged on the residual not
// clipped, that raises half B's total by far more than 2 %: the crack is not reported.
TEST(Diagnoser, ATermThatAddsLinesTheRecordingLacksIsNotReportedWhereTheResidualIsClipped) {
  md::RomEffectSimulator unused(paper(), 0.0);
  md::Diagnoser probe(paper(), unused);
  ToneEffectSimulator sim(probe.catalogue(), {.always = 4.0, .per_crack = 30.0});
  md::DiagnoserConfig cfg = config();
  cfg.calibration.max_rounds = 1;  // nothing to win: the always-there line is out of its reach
  md::Diagnoser d(paper(), sim, cfg);
  const Recording r = record(probe.catalogue(), drifted(), 0.08, 6.5, 3);
  ASSERT_EQ(run_to_end(d, r), md::DiagnosisStep::kFinished) << d.report().message;
  const md::DiagnosisReport& rep = d.report();
  EXPECT_EQ(rep.residual_calibrated, 1.0);  // clipped: the always-there line
  EXPECT_TRUE(rep.missing.empty());
  bool judged = false;
  for (const md::CandidateResult& c : rep.candidates) {
    if (c.effect != md::Effect::kToothCrack || c.location != "g4") continue;
    judged = true;
    EXPECT_FALSE(c.accepted);
    EXPECT_GT(c.guard_holdout_calibrated, 1.0);
    EXPECT_GT(c.guard_holdout_effect, 1.02 * c.guard_holdout_calibrated) << c.verdict;
  }
  EXPECT_TRUE(judged);
}

TEST(Diagnoser, CancelEndsTheRunAtTheNextStepAndTheSummarySaysSo) {
  md::RomEffectSimulator unused(paper(), 0.0);
  md::Diagnoser probe(paper(), unused);
  ToneEffectSimulator sim(probe.catalogue());
  md::Diagnoser d(paper(), sim, config());
  const Recording r = record(probe.catalogue(), drifted(), 0.0, 14.0, 3);
  md::DiagnosisSummary s;
  d.start(input_of(r));
  EXPECT_FALSE(d.read_result(s));                    // nothing before the first step
  ASSERT_EQ(d.step(), md::DiagnosisStep::kRunning);  // speed
  ASSERT_TRUE(d.read_result(s));
  EXPECT_FALSE(s.finished);
  EXPECT_EQ(s.stage, md::DiagnosisStage::kAnalyse);
  d.cancel();
  EXPECT_EQ(d.step(), md::DiagnosisStep::kCancelled);
  ASSERT_TRUE(d.read_result(s));
  EXPECT_TRUE(s.cancelled);
  EXPECT_TRUE(s.finished);
}

TEST(Diagnoser, RefusesARecordingShorterThanTheAnalysisNeeds) {
  md::RomEffectSimulator unused(paper(), 0.0);
  md::Diagnoser probe(paper(), unused);
  ToneEffectSimulator sim(probe.catalogue());
  md::Diagnoser d(paper(), sim, config());
  const Recording r = record(probe.catalogue(), drifted(), 0.0, 3.0, 4);  // 43 revolutions
  d.start(input_of(r));
  EXPECT_EQ(d.step(), md::DiagnosisStep::kFailed);
  EXPECT_EQ(d.report().status, md::DiagnosisStatus::kTooShort);
  EXPECT_NE(d.report().message.find("revolutions"), std::string::npos) << d.report().message;
}

}  // namespace
