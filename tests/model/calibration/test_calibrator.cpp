// The calibrator against simulators whose answer is known:
//  - ToneSimulator: mesh-harmonic tones whose log amplitudes are a known linear
//    function of the log parameters (the feature map the trust region models),
//    so the recording's parameters are recoverable exactly;
//  - the lumped stand-in: recordings simulated with known off-nominal
//    parameters, which the model reproduces up to the added noise.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <complex>
#include <cstdlib>
#include <memory>
#include <new>
#include <optional>
#include <span>
#include <vector>

#include "model/calibration/calibrator.hpp"
#include "model/calibration/lumped_simulator.hpp"
#include "model/calibration/resonance_placement.hpp"
#include "model/drivetrain/kinematics.hpp"

// GCC 12 at -O2 (with ASan) inlines the replaced operator delete below into
// gtest's code and then mistakes free() on operator new's malloc() for a
// mismatch; both are ours and match.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
namespace {
std::atomic<std::size_t> g_allocations{0};
}
void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace {

using namespace model::calibration;
using model::DynamicsParameters;

DynamicsParameters nominal_parameters() {
  DynamicsParameters p;
  p.rayleigh_eta = 2.0;    // [1/s]
  p.rayleigh_zeta = 2e-5;  // [s]
  return p;
}

// Table 3 style drift: damping ×2, mesh stiffness ×0.8, bearing stiffness ×1.3.
DynamicsParameters drifted_parameters() {
  DynamicsParameters p = nominal_parameters();
  p.rayleigh_eta *= 2.0;
  p.rayleigh_zeta *= 2.0;
  p.mesh_stiffness_scale = {0.8, 0.8, 0.8};
  p.bearing_stiffness_scale = {1.3, 1.3, 1.3};
  return p;
}

// The index of the variable that moves (field, index) in a space; the space's size when none does.
std::size_t variable_index(const CalibrationSpace& space, ParameterField field, std::size_t index) {
  for (std::size_t i = 0; i < space.size(); ++i) {
    if (space.variable(i).field == field && space.variable(i).index == index) return i;
  }
  return space.size();
}

// A small, quick configuration: 256 samples/rev × 32 revolutions.
model::dsp::FeatureConfig small_features() {
  model::dsp::FeatureConfig c;
  c.samples_per_rev = 256;
  c.revolutions = 32;
  c.harmonics = 3;
  return c;
}

// Every mesh tone (3 stages × 3 harmonics) at both points, amplitude
//   ln A_p,i = ln A0_p,i + Σ_j G_p,i,j · ln(θ_j / θ_nominal,j)
// over the 8 calibrated parameters θ, with fixed G (full column rank), so the
// feature map ln A is exactly linear in the optimiser's variables and the
// parameters that produced a recording are the unique exact fit.
class ToneSimulator : public VibrationSimulator {
 public:
  static constexpr double kSampleRateHz = 4096.0;  // > 2 × the 3rd hss mesh harmonic (1116 Hz)
  static constexpr std::size_t kTones = 9;
  ToneSimulator(const model::Drivetrain& d, double max_duration_s) : kinematics_(d) {
    for (auto& w : wave_) w.resize(static_cast<std::size_t>(max_duration_s * kSampleRateHz));
  }
  // Excitation mode: tone t of point p is also driven by transmission-error harmonic t as a
  // linear system would be, A = P + T·(e/e_ref)·exp(iφ), with fixed complex P (the stiffness
  // variation's own tone) and T (the path) per point and tone.
  void set_excitation(bool on) { excitation_ = on; }
  // Lines outside the compared tones, at point 1: the model's own line at order
  // kModelLineOrder, amplitude model_line·(1 − tip relief of stage 2) (a stiffness harmonic the
  // relief smooths out; no tone depends on the relief), and a line at kRecordingLineOrder
  // the model cannot make (a bearing line), amplitude recording_line.
  static constexpr double kModelLineOrder = 40.5;
  static constexpr double kRecordingLineOrder = 60.5;
  double model_line = 0.0;
  double recording_line = 0.0;
  static constexpr double kReferenceError = 1e-6;  // [m] e_ref
  static std::complex<double> parametric(std::size_t p, std::size_t t) {
    return std::polar(0.3, 0.7 * static_cast<double>(t) + static_cast<double>(p));
  }
  static std::complex<double> path(std::size_t p, std::size_t t) {
    return std::polar(1.0 + 0.5 * static_cast<double>(p),
                      1.1 * static_cast<double>(t) - 0.4 * static_cast<double>(p));
  }
  static double gain(std::size_t point, std::size_t tone, std::size_t param) {
    return 0.6 * std::sin(1.3 * static_cast<double>(1 + tone + 9 * point) *
                              static_cast<double>(1 + param) +
                          0.4);
  }
  bool simulate(const DynamicsParameters& params, const OperatingPoint& op, double duration_s,
                std::array<WaveformView, kMeasurementPoints>& out) override {
    const auto n = static_cast<std::size_t>(duration_s * kSampleRateHz);
    if (n > wave_[0].size()) return false;
    std::array<double, 8> x{};
    const DynamicsParameters nominal = nominal_parameters();
    x[0] = std::log(params.rayleigh_eta / nominal.rayleigh_eta);
    x[1] = std::log(params.rayleigh_zeta / nominal.rayleigh_zeta);
    for (std::size_t s = 0; s < 3; ++s) {
      x[2 + s] = std::log(params.mesh_stiffness_scale[s]);
      x[5 + s] = std::log(params.bearing_stiffness_scale[s]);
    }
    for (std::size_t p = 0; p < kMeasurementPoints; ++p) {
      std::fill(wave_[p].begin(), wave_[p].begin() + static_cast<long>(n), 0.0);
      for (std::size_t t = 0; t < kTones; ++t) {
        double log_a = std::log(0.1 / static_cast<double>(1 + t % 3)) + (p == 0 ? 0.0 : -0.5);
        for (std::size_t j = 0; j < 8; ++j) log_a += gain(p, t, j) * x[j];
        const double f_hz =
            static_cast<double>(1 + t % 3) * kinematics_.mesh_hz(t / 3, op.rotor_speed_rpm);
        const double w = 2.0 * 3.14159265358979323846 * f_hz / kSampleRateHz;
        // A·cos(w·i + φ) by a rotating phasor (cheap under QEMU; drift ~1e-12 over a recording).
        const double a = std::exp(log_a);
        std::complex<double> z = std::polar(a, 0.3 * static_cast<double>(t));
        if (excitation_) {
          z = a * (parametric(p, t) +
                   path(p, t) * std::polar(params.transmission_error_m[t] / kReferenceError,
                                           params.transmission_error_phase_rad[t]));
        }
        double re = z.real();
        double im = z.imag();
        const double c = std::cos(w);
        const double sn = std::sin(w);
        for (std::size_t i = 0; i < n; ++i) {
          wave_[p][i] += re;
          const double next_re = re * c - im * sn;
          im = re * sn + im * c;
          re = next_re;
        }
      }
      const double hss_hz = op.rotor_speed_rpm / 60.0 * kinematics_.overall_ratio();
      if (p == 0) {
        add_line(wave_[p], n, kModelLineOrder * hss_hz,
                 model_line * (1.0 - params.mesh_tip_relief[1]));
        add_line(wave_[p], n, kRecordingLineOrder * hss_hz, recording_line);
      }
      out[p] = {wave_[p].data(), n, kSampleRateHz};
    }
    return true;
  }

 private:
  static void add_line(std::vector<double>& w, std::size_t n, double f_hz, double a) {
    if (a == 0.0) return;
    const double dw = 2.0 * 3.14159265358979323846 * f_hz / kSampleRateHz;
    for (std::size_t i = 0; i < n; ++i) w[i] += a * std::cos(dw * static_cast<double>(i) + 0.2);
  }
  model::Kinematics kinematics_;
  std::array<std::vector<double>, kMeasurementPoints> wave_;
  bool excitation_ = false;
};

class ToneCalibratorTest : public ::testing::Test {
 protected:
  // Runs end at convergence (no restarts) or, with `stop_at_fit`, at the first fitting evaluation.
  std::unique_ptr<Calibrator> make(const DynamicsParameters& truth, std::uint64_t seed = 0,
                                   std::size_t budget = 40, bool stop_at_fit = false) {
    CalibratorConfig cc = paper_config(seed, budget, stop_at_fit);
    return make_with(truth, cc, {&op_, 1});
  }
  static CalibratorConfig paper_config(std::uint64_t seed = 0, std::size_t budget = 40,
                                       bool stop_at_fit = false) {
    CalibratorConfig cc;
    cc.method = CalibrationMethod::kTrustRegion;
    cc.trust_region.seed = seed;
    cc.trust_region.max_evaluations = budget;
    cc.trust_region.restarts = false;
    cc.stop_at_threshold = stop_at_fit;
    // The map depends on the paper's 8 variables only, exactly and with full rank: the exact
    // fit is unique, so no regularisation toward a prior (which would bias it).
    cc.space = CalibrationSpace::paper(nominal_parameters());
    cc.prior_weight = 0.0;
    return cc;
  }
  // A calibrator of `cc` against recordings of `truth` at each operating point (joint when
  // more than one).
  // With `spectra`, each point's order spectrum is given too (the spectral residual ρ).
  std::unique_ptr<Calibrator> make_with(const DynamicsParameters& truth, const CalibratorConfig& cc,
                                        std::span<const OperatingPoint> ops, bool spectra = false) {
    auto cal = std::make_unique<Calibrator>(simulator_, drivetrain_, small_features(), cc);
    std::vector<CalibrationCase> cases(ops.size());
    std::vector<std::vector<double>> spectrum(ops.size() * kMeasurementPoints);
    for (std::size_t c = 0; c < ops.size(); ++c) {
      std::array<WaveformView, kMeasurementPoints> w{};
      EXPECT_TRUE(simulator_.simulate(truth, ops[c], 3.0, w));
      // The views point into the simulator's buffers: extract before the calibrator simulates.
      model::dsp::FeatureExtractor fx(cal->feature_config());
      const double hss_hz =
          ops[c].rotor_speed_rpm / 60.0 * model::Kinematics(drivetrain_).overall_ratio();
      for (std::size_t p = 0; p < kMeasurementPoints; ++p) {
        EXPECT_EQ(fx.extract(w[p].samples, w[p].count, w[p].sample_rate_hz, {nullptr, 0, hss_hz},
                             cases[c].measured[p]),
                  model::dsp::DspStatus::kOk);
        const std::size_t lines =
            cal->feature_config().samples_per_rev * cal->feature_config().revolutions / 2 + 1;
        spectrum[c * kMeasurementPoints + p].assign(fx.order_spectrum(),
                                                    fx.order_spectrum() + lines);
      }
      cases[c].op = ops[c];
    }
    EXPECT_TRUE(cal->set_measurements(cases.data(), cases.size()));
    for (std::size_t i = 0; spectra && i < spectrum.size(); ++i) {
      EXPECT_TRUE(cal->set_measured_spectrum(i / kMeasurementPoints, i % kMeasurementPoints,
                                             spectrum[i].data(), spectrum[i].size()));
    }
    return cal;
  }
  static CalibrationResult run(Calibrator& cal, const DynamicsParameters& current,
                               const std::optional<DynamicsParameters>& previous = std::nullopt,
                               const FeatureJacobian* model = nullptr) {
    EXPECT_TRUE(cal.start(current, previous, model));
    while (cal.step() == StepStatus::kRunning) {
    }
    CalibrationResult r;
    EXPECT_TRUE(cal.read_result(r));
    return r;
  }

  model::Drivetrain drivetrain_ = model::paper_2mw();
  OperatingPoint op_{8.33, 361747.0};
  ToneSimulator simulator_{drivetrain_, 4.0};
};

TEST_F(ToneCalibratorTest, TheTrustRegionRecoversTheParametersThatProducedTheRecording) {
  // Arrange
  auto cal = make(drifted_parameters());
  PointIndicators before{};
  ASSERT_TRUE(cal->evaluate(nominal_parameters(), before));
  ASSERT_TRUE(needs_calibration(before));
  // Act
  const CalibrationResult r = run(*cal, nominal_parameters());
  // Assert: within 1 % of the truth (the map is exact; the residual is the FFT's leakage).
  EXPECT_TRUE(r.fits);
  EXPECT_GT(r.evaluations_to_threshold, 0u);
  const DynamicsParameters truth = drifted_parameters();
  EXPECT_NEAR(r.parameters.rayleigh_eta / truth.rayleigh_eta, 1.0, 0.01);
  EXPECT_NEAR(r.parameters.rayleigh_zeta / truth.rayleigh_zeta, 1.0, 0.01);
  for (std::size_t s = 0; s < 3; ++s) {
    EXPECT_NEAR(r.parameters.mesh_stiffness_scale[s] / truth.mesh_stiffness_scale[s], 1.0, 0.01)
        << s;
    EXPECT_NEAR(r.parameters.bearing_stiffness_scale[s] / truth.bearing_stiffness_scale[s], 1.0,
                0.01)
        << s;
  }
  for (const Indicators& i : r.indicators) EXPECT_LT(worst_threshold_ratio(i), 0.1);
}

TEST_F(ToneCalibratorTest, AWarmStartWithThePreviousModelRecalibratesInFarFewerEvaluations) {
  // Arrange: yesterday's calibration (half the drift), then today's recording (the whole drift).
  DynamicsParameters yesterday = nominal_parameters();
  yesterday.rayleigh_eta *= std::sqrt(2.0);
  yesterday.rayleigh_zeta *= std::sqrt(2.0);
  yesterday.mesh_stiffness_scale.fill(std::sqrt(0.8));
  yesterday.bearing_stiffness_scale.fill(std::sqrt(1.3));
  auto first = make(yesterday);
  const CalibrationResult previous = run(*first, nominal_parameters());
  ASSERT_TRUE(previous.fits);
  FeatureJacobian model;
  ASSERT_TRUE(first->feature_model(model));
  auto cold = make(drifted_parameters(), 0, 40, true);
  auto warm = make(drifted_parameters(), 0, 40, true);
  // Act
  const CalibrationResult c = run(*cold, nominal_parameters());
  const CalibrationResult w = run(*warm, nominal_parameters(), previous.parameters, &model);
  // Assert: cold needs its 8 probes first; warm steps at once with a model that is
  // exact for this linear map (up to the RMS feature), so its first step fits.
  EXPECT_TRUE(w.fits);
  EXPECT_GE(c.evaluations_to_threshold, 9u);
  EXPECT_LE(w.evaluations_to_threshold, 2u);
}

TEST_F(ToneCalibratorTest, WarmRoundsSkipTheProbesAndReachTheSameFitOnAMapWithAConstantJacobian) {
  // Arrange: 2 fit evaluations a round, so the drift takes several rounds. The tones' map is
  // linear in the variables: a round's probes learn nothing the last round's model did not
  // (Broyden's update leaves an exact J as it is), so skipping them loses nothing.
  CalibratorConfig warm_cc = paper_config(0, 2);
  warm_cc.max_rounds = 12;
  // The 1 % rule alone: on this exact map F falls below one unit of χ² within a few rounds,
  // after which the χ² rule ends both runs (RoundsStopWhenTheyLowerFByLessThanOneUnitOfChiSquare);
  // the rounds compared here are the 1 % rule's.
  warm_cc.min_round_gain = 0.0;
  CalibratorConfig probed_cc = warm_cc;
  probed_cc.warm_rounds = false;
  auto warm = make_with(drifted_parameters(), warm_cc, {&op_, 1});
  auto probed = make_with(drifted_parameters(), probed_cc, {&op_, 1});
  // Act
  const CalibrationResult w = run(*warm, nominal_parameters());
  const CalibrationResult p = run(*probed, nominal_parameters());
  // Assert: both recover the truth within 1 % (the map is exact)…
  const DynamicsParameters truth = drifted_parameters();
  for (const CalibrationResult* r : {&w, &p}) {
    EXPECT_TRUE(r->fits);
    EXPECT_NEAR(r->parameters.rayleigh_eta / truth.rayleigh_eta, 1.0, 0.01);
    for (std::size_t s = 0; s < 3; ++s) {
      EXPECT_NEAR(r->parameters.mesh_stiffness_scale[s] / truth.mesh_stiffness_scale[s], 1.0, 0.01);
      EXPECT_NEAR(r->parameters.bearing_stiffness_scale[s] / truth.bearing_stiffness_scale[s], 1.0,
                  0.01);
    }
  }
  // …to the same least F (the map's floor, FFT leakage)…
  EXPECT_NEAR(w.cost / p.cost, 1.0, 0.01);
  // …every round of the probed run probes (1 start + 8 probes + at most 2 fit evaluations);
  // the warm run probes only its first round and those after a round that did not improve,
  // so it spends at least one round's 8 probes less, and it settles only on a freshly probed
  // model (a warm round that does not improve is followed by a probed one: ≥ 2 probed);
  // neither spends more than 12 probed rounds' evaluations.
  EXPECT_GT(p.rounds, 2u);
  EXPECT_EQ(p.probed_rounds, p.rounds);
  EXPECT_LE(p.evaluations, p.rounds * 11u);
  EXPECT_LT(w.probed_rounds, w.rounds);
  EXPECT_GE(w.probed_rounds, 2u);
  EXPECT_LE(w.evaluations + 8u, p.evaluations);
  EXPECT_LE(w.evaluations, 12u * 11u);
}

TEST_F(ToneCalibratorTest, RoundsStopWhenTheyLowerFByLessThanOneUnitOfChiSquare) {
  // Arrange: the drift of the warm-rounds test, 2 fit evaluations a round. F is a χ² (tones
  // weighted by their σ), so a round that lowers it by less than 1 gains nothing the data can
  // tell from noise. On this exact map F falls to the FFT leakage floor (≪ 1), where the
  // 1 % rule alone still counts every further round as an improvement.
  CalibratorConfig percent_cc = paper_config(0, 2);
  percent_cc.max_rounds = 12;
  percent_cc.min_round_gain = 0.0;  // the 1 % rule alone
  CalibratorConfig chi2_cc = percent_cc;
  chi2_cc.min_round_gain = 1.0;
  auto percent = make_with(drifted_parameters(), percent_cc, {&op_, 1});
  auto chi2 = make_with(drifted_parameters(), chi2_cc, {&op_, 1});
  // Act
  const CalibrationResult a = run(*percent, nominal_parameters());
  const CalibrationResult b = run(*chi2, nominal_parameters());
  // Assert: both fit and recover the truth within 1 %…
  const DynamicsParameters truth = drifted_parameters();
  for (const CalibrationResult* r : {&a, &b}) {
    EXPECT_TRUE(r->fits);
    EXPECT_NEAR(r->parameters.rayleigh_eta / truth.rayleigh_eta, 1.0, 0.01);
    for (std::size_t s = 0; s < 3; ++s)
      EXPECT_NEAR(r->parameters.mesh_stiffness_scale[s] / truth.mesh_stiffness_scale[s], 1.0, 0.01);
  }
  // …the χ² rule stops rounds earlier, at no loss the data could show: what the further
  // rounds of the 1 % rule gain on this map is less than one unit of χ².
  EXPECT_LT(b.rounds, a.rounds);
  EXPECT_LT(b.evaluations, a.evaluations);
  EXPECT_LE(a.cost, b.cost);
  EXPECT_LT(b.cost - a.cost, 1.0);
}

TEST_F(ToneCalibratorTest, TheTrustRegionIsDeterministic) {
  // The calibrator probes along its variables itself and the seed only draws restart points
  // (none here): two runs of one configuration give the same evaluations, bit for bit.
  auto a = make(drifted_parameters(), 9, 11);
  auto b = make(drifted_parameters(), 9, 11);
  const CalibrationResult ra = run(*a, nominal_parameters());
  const CalibrationResult rb = run(*b, nominal_parameters());
  EXPECT_GT(ra.evaluations, 9u);  // the start and 8 probes, then the fit
  EXPECT_EQ(ra.evaluations, rb.evaluations);
  EXPECT_EQ(ra.parameters.rayleigh_eta, rb.parameters.rayleigh_eta);
  EXPECT_EQ(ra.parameters.bearing_stiffness_scale, rb.parameters.bearing_stiffness_scale);
  EXPECT_EQ(ra.indicators[1].f3, rb.indicators[1].f3);
}

TEST_F(ToneCalibratorTest, CancelStopsTheTrustRegionAtTheNextStepAndPublishesACancelledResult) {
  auto cal = make(drifted_parameters());
  ASSERT_TRUE(cal->start(nominal_parameters()));
  ASSERT_EQ(cal->step(), StepStatus::kRunning);
  ASSERT_EQ(cal->step(), StepStatus::kRunning);
  cal->cancel();
  EXPECT_EQ(cal->step(), StepStatus::kCancelled);
  CalibrationResult r;
  ASSERT_TRUE(cal->read_result(r));
  EXPECT_TRUE(r.cancelled);
  EXPECT_EQ(r.evaluations, 2u);
}

TEST_F(ToneCalibratorTest, TrustRegionStepsDoNotAllocate) {
  auto cal = make(drifted_parameters(), 0, 11);
  ASSERT_TRUE(cal->start(nominal_parameters()));
  const std::size_t before = g_allocations.load();
  while (cal->step() == StepStatus::kRunning) {
  }
  EXPECT_EQ(g_allocations.load(), before);
}

TEST_F(ToneCalibratorTest, VariablesTheRecordingCannotDetermineAreReportedAndKeptAtTheirPriors) {
  // The standard space (66 variables with transmission error and housing modes in the prior);
  // the tones depend on η, ζ and the mesh scales only, so those 5 are identified and every
  // other variable must be reported not identified and left exactly at its prior.
  DynamicsParameters prior = model::paper_2mw().dynamics;
  prior.rayleigh_eta = nominal_parameters().rayleigh_eta;
  prior.rayleigh_zeta = nominal_parameters().rayleigh_zeta;
  DynamicsParameters truth = prior;
  truth.rayleigh_eta *= 2.0;
  truth.rayleigh_zeta *= 2.0;
  truth.mesh_stiffness_scale = {0.8, 0.8, 0.8};
  CalibratorConfig cc = paper_config(0, 40);
  cc.space = CalibrationSpace::standard(prior);
  cc.prior_weight = 1.0;  // the prior as stated: the estimate is biased toward it, slightly
  auto cal = make_with(truth, cc, {&op_, 1});
  const CalibrationResult r = run(*cal, prior);
  ASSERT_EQ(r.variables, cc.space.size());
  std::size_t identified = 0;
  for (std::size_t i = 0; i < cc.space.size(); ++i) {
    const CalibrationVariable& v = cc.space.variable(i);
    const bool depends = v.field == ParameterField::kRayleighEta ||
                         v.field == ParameterField::kRayleighZeta ||
                         v.field == ParameterField::kMeshScale;
    if (depends) {
      EXPECT_EQ(r.status[i], VariableStatus::kIdentified) << cc.space.name(i);
      identified += r.status[i] == VariableStatus::kIdentified ? 1 : 0;
    } else {
      EXPECT_EQ(r.status[i], VariableStatus::kNotIdentified) << cc.space.name(i);
      // At the prior up to the round trip through the whitened logarithm.
      const double p0 = CalibrationSpace::get(prior, v);
      EXPECT_NEAR(CalibrationSpace::get(r.parameters, v), p0, 1e-9 * std::max(1.0, std::abs(p0)))
          << cc.space.name(i);
    }
  }
  EXPECT_EQ(identified, 5u);
  EXPECT_EQ(r.identified, 5u);
  EXPECT_TRUE(r.fits);
  // The prior's pull: a few per cent at most against 18 tones weighted 1/0.1.
  EXPECT_NEAR(r.parameters.rayleigh_zeta / truth.rayleigh_zeta, 1.0, 0.05);
  for (std::size_t s = 0; s < 3; ++s)
    EXPECT_NEAR(r.parameters.mesh_stiffness_scale[s] / truth.mesh_stiffness_scale[s], 1.0, 0.05);
}

TEST_F(ToneCalibratorTest, AVariableTheRecordingPushesPastItsBoundIsReportedAtTheBound) {
  // The truth's high-speed mesh scale 0.3 lies below the space's bound 0.5: the fit must end
  // on the bound and say so, never claim a calibration.
  DynamicsParameters truth = nominal_parameters();
  truth.mesh_stiffness_scale[2] = 0.3;
  auto cal = make(truth);
  const CalibrationResult r = run(*cal, nominal_parameters());
  const CalibrationSpace space = CalibrationSpace::paper(nominal_parameters());
  const std::size_t hss = variable_index(space, ParameterField::kMeshScale, 2);
  ASSERT_LT(hss, space.size());
  EXPECT_EQ(r.status[hss], VariableStatus::kAtLowerBound);
  EXPECT_NEAR(r.parameters.mesh_stiffness_scale[2], 0.5, 1e-3);
  EXPECT_TRUE(r.at_bound);
}

TEST_F(ToneCalibratorTest, AFitInsideTheBoundsIsChosenOverACloserOneOnTheBound) {
  // The truth's high-speed mesh scale 0.48 lies just below the space's bound 0.5: the bound
  // matches the tones best, but a point inside fits within every threshold too (ln(0.52/0.48)
  // moves a tone by |G| · 0.08 ≤ 5 %, far inside f1–f3's limits). A point on a bound is no
  // success, so the chosen calibration is a fit inside the bounds, and it is a calibration.
  DynamicsParameters truth = nominal_parameters();
  truth.mesh_stiffness_scale[2] = 0.48;
  auto cal = make(truth);
  const CalibrationResult r = run(*cal, nominal_parameters());
  const CalibrationSpace space = CalibrationSpace::paper(nominal_parameters());
  EXPECT_TRUE(r.fits);
  EXPECT_FALSE(r.at_bound);
  const std::size_t hss = variable_index(space, ParameterField::kMeshScale, 2);
  ASSERT_LT(hss, space.size());
  EXPECT_EQ(r.status[hss], VariableStatus::kIdentified);
  EXPECT_GT(r.parameters.mesh_stiffness_scale[2], 0.5);
  for (const Indicators& i : r.indicators) EXPECT_LT(worst_threshold_ratio(i), 1.0);
}

TEST_F(ToneCalibratorTest, AJointCalibrationFitsOneParameterSetToTwoOperatingPoints) {
  const std::array<OperatingPoint, 2> ops{{{8.33, 361747.0}, {14.8, 1.23e6}}};
  auto cal = make_with(drifted_parameters(), paper_config(0, 40), ops);
  ASSERT_EQ(cal->cases(), 2u);
  const CalibrationResult r = run(*cal, nominal_parameters());
  EXPECT_EQ(r.cases, 2u);
  EXPECT_TRUE(r.fits);
  for (std::size_t c = 0; c < 2; ++c) {
    for (const Indicators& i : r.case_indicators[c]) EXPECT_LT(worst_threshold_ratio(i), 0.1) << c;
  }
  EXPECT_NEAR(r.parameters.mesh_stiffness_scale[1] / 0.8, 1.0, 0.01);
}

TEST_F(ToneCalibratorTest, TheExcitationSolveMatchesEveryToneFromItsParametricAndPathParts) {
  // Tones A = P + T·e·exp(iφ) (the ToneSimulator's excitation mode), the recording's errors
  // 0.2–5 × the prior with phases all round: the solve (one evaluation for P, one for T) must
  // bring every tone at both points within 2 % by its third evaluation, before any probe.
  simulator_.set_excitation(true);
  DynamicsParameters prior = nominal_parameters();
  prior.transmission_error_m.fill(ToneSimulator::kReferenceError);
  DynamicsParameters truth = prior;
  constexpr std::array<double, 9> kScale{3.0, 0.2, 1.5, 5.0, 0.5, 0.8, 0.3, 2.5, 1.2};
  constexpr std::array<double, 9> kPhase{2.0, -1.0, 0.5, -2.8, 1.4, 3.0, -0.3, -1.9, 0.9};
  for (std::size_t t = 0; t < 9; ++t) {
    truth.transmission_error_m[t] *= kScale[t];
    truth.transmission_error_phase_rad[t] = kPhase[t];
  }
  CalibratorConfig cc = paper_config(0, 20, true);
  cc.space = CalibrationSpace::standard(prior);
  cc.prior_weight = 1.0;
  auto cal = make_with(truth, cc, {&op_, 1});
  PointIndicators before{};
  ASSERT_TRUE(cal->evaluate(prior, before));
  ASSERT_TRUE(needs_calibration(before));
  const CalibrationResult r = run(*cal, prior);
  EXPECT_TRUE(r.fits);
  EXPECT_GT(r.evaluations_to_threshold, 0u);
  EXPECT_LE(r.evaluations_to_threshold, 3u);
  for (const Indicators& i : r.indicators) EXPECT_LT(i.f3, 0.02);
}

TEST_F(ToneCalibratorTest, CalibratingTheModelsOwnRecordingAtItsParametersMovesNothing) {
  // The null test: the recording is the model's own at the starting parameters (excitation
  // included); a calibration forced on it must find nothing to move — every variable within
  // 1e-3 prior σ of where it started — and fit everywhere.
  simulator_.set_excitation(true);
  DynamicsParameters start = nominal_parameters();
  start.transmission_error_m.fill(2.0 * ToneSimulator::kReferenceError);
  start.transmission_error_phase_rad.fill(0.7);
  CalibratorConfig cc = paper_config(0, 20);
  cc.space = CalibrationSpace::standard(start);
  cc.prior_weight = 1.0;
  auto cal = make_with(start, cc, {&op_, 1});
  const CalibrationResult r = run(*cal, start);
  EXPECT_TRUE(r.fits);
  std::array<double, kMaxCalibrationVariables> z0{};
  cc.space.to_variables(start, z0.data());
  std::array<double, kMaxCalibrationVariables> z1{};
  cc.space.to_variables(r.parameters, z1.data());
  for (std::size_t i = 0; i < cc.space.size(); ++i)
    EXPECT_NEAR(z1[i], z0[i], 1e-3) << cc.space.name(i);
}

TEST_F(ToneCalibratorTest, TheSpectralResidualIsTheShareOfTheRecordedEnergyTheModelLeavesOut) {
  // Arrange: the recording has the tones and a line the model cannot make (B = 0.2 at point 1);
  // the model has the tones and a line the recording lacks (A = 0.3 at point 1).
  simulator_.recording_line = 0.2;
  CalibratorConfig cc = paper_config();
  cc.residual_model_sd = 0.5;
  auto cal = make_with(nominal_parameters(), cc, {&op_, 1}, true);
  simulator_.recording_line = 0.0;
  simulator_.model_line = 0.3;
  // Act
  PointIndicators ind{};
  ASSERT_TRUE(cal->evaluate(nominal_parameters(), ind));
  // Assert: by Parseval every line's spectrum sums to A²·(the window's noise bandwidth), the
  // same factor for every line, so ρ² = Σ(missed lines' A²) / Σ(recorded lines' A²): at point 1
  // (0.3² + 0.2²) / (Σ tones' A² + 0.2²), the tones 0.1/h (h = 1, 2, 3) of each of 3 meshes;
  // at point 2 the spectra are equal.
  const double tones = 3.0 * (0.01 + 0.0025 + 0.01 / 9.0);
  const double expected = (0.09 + 0.04) / (tones + 0.04);
  EXPECT_NEAR(cal->residual_share(0, 0), expected, 0.02 * expected);  // leakage between lines
  EXPECT_LT(cal->residual_share(0, 1), 1e-6);
}

TEST_F(ToneCalibratorTest, ALineOnlyTheModelMakesIsFittedAwayWhenTheFitSeesTheSpectralResidual) {
  // The model's extra line falls with stage 2's tip relief, which no compared tone depends on;
  // the recording was made at relief 0.5 (line 0.2), the calibration starts at the prior 0
  // (line 0.4). The RMS alone carries too little information to identify the relief
  // (‖∂(ln RMS)/∂z‖²/σ_RMS² ≈ 1.3 < 3, posterior σ above half the prior's); with ρ (σ_ρ 0.25)
  // it is identified, and it ends where the cost along it is least — the hand-derived
  // F(z) = ((ln RMS(z) − ln RMS*)/σ_RMS)² + (ρ(z)/σ_ρ)² + z², with RMS² = Σ A_tone²/2 + a²/2,
  // ρ = |a − a*| / √(Σ A_tone² + a*²), a = 0.4·(1 − relief), relief = 0.35·z — at 0.426,
  // short of the truth by the prior's pull.
  DynamicsParameters prior = model::paper_2mw().dynamics;
  prior.rayleigh_eta = nominal_parameters().rayleigh_eta;
  prior.rayleigh_zeta = nominal_parameters().rayleigh_zeta;
  prior.mesh_tip_relief = {0.0, 0.0, 0.0};
  DynamicsParameters truth = prior;
  truth.mesh_tip_relief[1] = 0.5;
  CalibratorConfig cc = paper_config(0, 40);
  cc.space = CalibrationSpace::standard(prior);
  cc.prior_weight = 1.0;
  cc.residual_model_sd = 0.25;
  std::size_t relief = cc.space.size();
  for (std::size_t i = 0; i < cc.space.size(); ++i) {
    if (cc.space.variable(i).field == ParameterField::kMeshTipRelief &&
        cc.space.variable(i).index == 1)
      relief = i;
  }
  ASSERT_LT(relief, cc.space.size());
  simulator_.model_line = 0.4;
  // Hand minimum of F along the relief.
  const double tones = 3.0 * (0.01 + 0.0025 + 0.01 / 9.0);
  const double a_true = 0.4 * 0.5;
  auto cost = [&](double r) {
    const double a = 0.4 * (1.0 - r);
    const double ln_rms = 0.5 * std::log(0.5 * tones + 0.5 * a * a);
    const double ln_rms_true = 0.5 * std::log(0.5 * tones + 0.5 * a_true * a_true);
    const double rho = std::abs(a - a_true) / std::sqrt(tones + a_true * a_true);
    const double z = r / 0.35;
    return std::pow((ln_rms - ln_rms_true) / 0.25, 2) + std::pow(rho / 0.25, 2) + z * z;
  };
  double expected = 0.0;
  for (double r = 0.0; r <= 1.0; r += 1e-4) expected = cost(r) < cost(expected) ? r : expected;
  // Act
  auto blind = make_with(truth, cc, {&op_, 1}, false);
  const CalibrationResult without = run(*blind, prior);
  auto seeing = make_with(truth, cc, {&op_, 1}, true);
  const CalibrationResult with = run(*seeing, prior);
  // Assert
  EXPECT_EQ(without.status[relief], VariableStatus::kNotIdentified);
  EXPECT_EQ(without.parameters.mesh_tip_relief[1], 0.0);
  EXPECT_EQ(with.status[relief], VariableStatus::kIdentified);
  EXPECT_NEAR(with.parameters.mesh_tip_relief[1], expected, 0.01);
  EXPECT_LT(seeing->residual_share(0, 0),
            0.2 * std::pow(0.4 - a_true, 2) / (tones + a_true * a_true));
  EXPECT_TRUE(with.fits);
}

class CalibratorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // The "recording": drifted parameters, 5 % noise, at the paper's operating point.
    LumpedSimulatorConfig rec;
    rec.sample_rate_hz = 8192.0;
    rec.noise_relative = 0.05;
    recorder_ = std::make_unique<LumpedSimulator>(drivetrain_, rec);
    LumpedSimulatorConfig sim;
    sim.sample_rate_hz = 4096.0;
    simulator_ = std::make_unique<LumpedSimulator>(drivetrain_, sim);
  }

  std::unique_ptr<Calibrator> make(CalibrationMethod method, std::size_t population,
                                   std::size_t iterations, std::uint64_t seed = 5) {
    CalibratorConfig cc;
    cc.method = method;
    cc.mogoa.population = population;
    cc.mogoa.max_iterations = iterations;
    cc.mogoa.seed = seed;
    // The lumped stand-in has the paper's 8 variables only.
    cc.space = CalibrationSpace::paper(nominal_parameters());
    auto cal = std::make_unique<Calibrator>(*simulator_, drivetrain_, small_features(), cc);
    // Measured features, extracted with the calibrator's own configuration.
    std::array<WaveformView, kMeasurementPoints> w{};
    EXPECT_TRUE(recorder_->simulate(drifted_parameters(), op_, 4.0, w));
    model::dsp::FeatureExtractor fx(cal->feature_config());
    std::array<model::dsp::PointFeatures, kMeasurementPoints> measured{};
    const double hss_hz =
        op_.rotor_speed_rpm / 60.0 * model::Kinematics(drivetrain_).overall_ratio();
    for (std::size_t p = 0; p < kMeasurementPoints; ++p) {
      EXPECT_EQ(fx.extract(w[p].samples, w[p].count, w[p].sample_rate_hz, {nullptr, 0, hss_hz},
                           measured[p]),
                model::dsp::DspStatus::kOk);
    }
    cal->set_measurement(measured, op_);
    return cal;
  }

  model::Drivetrain drivetrain_ = model::paper_2mw();
  OperatingPoint op_{8.33, 361747.0};  // paper check point
  std::unique_ptr<LumpedSimulator> recorder_;
  std::unique_ptr<LumpedSimulator> simulator_;
};

TEST(CalibrationTrigger, FiresWhenAnyIndicatorOfEitherPointExceedsItsThreshold) {
  PointIndicators ok{};
  for (auto& i : ok) i = {0.4, 0.1, 0.1, true, 9};
  EXPECT_FALSE(needs_calibration(ok));
  PointIndicators f3_high = ok;
  f3_high[1].f3 = 0.21;
  EXPECT_TRUE(needs_calibration(f3_high));
  PointIndicators f1_high = ok;
  f1_high[0].f1 = 0.51;
  EXPECT_TRUE(needs_calibration(f1_high));
  PointIndicators invalid = ok;
  invalid[0].valid = false;
  EXPECT_TRUE(needs_calibration(invalid));
}

TEST(CalibrationSpace, RoundTripsParametersThroughItsWhitenedLogarithmicVariables) {
  // The paper's space around the nominal prior: η doubled is z = ln 2 / σ with σ = ln 2 (one
  // prior σ); a mesh scale 0.8 is ln 0.8 / 0.25; back to the same parameters.
  const CalibrationSpace space = CalibrationSpace::paper(nominal_parameters());
  ASSERT_EQ(space.size(), 8u);
  const DynamicsParameters p = drifted_parameters();
  std::array<double, kMaxCalibrationVariables> z{};
  space.to_variables(p, z.data());
  EXPECT_NEAR(z[0], 1.0, 1e-12);
  EXPECT_NEAR(z[2], std::log(0.8) / 0.25, 1e-12);
  const DynamicsParameters back = space.to_parameters(z.data(), p);
  EXPECT_NEAR(back.rayleigh_eta, 4.0, 1e-12);
  EXPECT_NEAR(back.rayleigh_zeta, 4e-5, 1e-17);
  for (std::size_t s = 0; s < 3; ++s) {
    EXPECT_NEAR(back.mesh_stiffness_scale[s], 0.8, 1e-12);
    EXPECT_NEAR(back.bearing_stiffness_scale[s], 1.3, 1e-12);
  }
}

TEST(CalibrationSpace,
     TheStandardSpaceHasEveryPhysicalVariableOnceAndOnlyErrorAmplitudesReachZero) {
  // paper-2mw's prior: 2 Rayleigh + 3 band + 3 mesh scale + 3 tip relief + 6 bearings + the
  // fluctuation + 9 transmission errors and 9 phases + 6 housing modes × 5 = 66.
  const CalibrationSpace space = CalibrationSpace::standard(model::paper_2mw().dynamics);
  ASSERT_EQ(space.size(), 66u);
  std::size_t relief = 0, zero_lower = 0;
  for (std::size_t i = 0; i < space.size(); ++i) {
    const auto& v = space.variable(i);
    if (v.field == model::calibration::ParameterField::kMeshTipRelief) {
      ++relief;
      EXPECT_FALSE(v.logarithmic);
      EXPECT_EQ(v.lower, 0.0);
      EXPECT_EQ(v.upper, 1.0);
    }
    // Only an error amplitude's lower bound (prior/50, searched in ln) and the varying
    // compliance's (prior/100: no fluctuation) stand for zero.
    EXPECT_EQ(v.lower_is_zero,
              v.field == model::calibration::ParameterField::kTransmissionError ||
                  v.field == model::calibration::ParameterField::kBearingComplianceScale)
        << space.name(i);
    zero_lower += v.lower_is_zero ? 1 : 0;
  }
  EXPECT_EQ(relief, 3u);
  EXPECT_EQ(zero_lower, 9u);
}

TEST(CalibrationSpace, TheDerivedVaryingComplianceIsOneScaleWithAWidePriorThatMayReachZero) {
  // A description with the varying compliance derived from the bearings' geometry
  // (bearing_compliance_scale 1) instead of the cosine: the space calibrates its scale, ln,
  // σ = ln 10 (the unknown operating clearance moves it ×100 over its physical range),
  // bounds ×/÷ 100, the lower one standing for "none" (not AT BOUND); the same 66 variables.
  model::DynamicsParameters p = model::paper_2mw().dynamics;
  p.bearing_compliance_scale = 1.0;
  p.bearing_stiffness_fluctuation = 0.0;
  const CalibrationSpace space = CalibrationSpace::standard(p);
  ASSERT_EQ(space.size(), 66u);
  std::size_t found = 0;
  for (std::size_t i = 0; i < space.size(); ++i) {
    const auto& v = space.variable(i);
    EXPECT_NE(v.field, model::calibration::ParameterField::kBearingFluctuation);
    if (v.field != model::calibration::ParameterField::kBearingComplianceScale) continue;
    ++found;
    EXPECT_TRUE(v.logarithmic);
    EXPECT_NEAR(v.prior_sd, std::log(10.0), 1e-12);
    EXPECT_NEAR(v.lower, 0.01, 1e-12);
    EXPECT_NEAR(v.upper, 100.0, 1e-9);
    EXPECT_TRUE(v.lower_is_zero);
  }
  EXPECT_EQ(found, 1u);
  double z[model::calibration::kMaxCalibrationVariables] = {};
  for (std::size_t i = 0; i < space.size(); ++i) {
    if (space.variable(i).field == model::calibration::ParameterField::kBearingComplianceScale)
      z[i] = 1.0;  // one prior σ up: ×10
  }
  EXPECT_NEAR(space.to_parameters(z, p).bearing_compliance_scale, 10.0, 1e-9);
}

TEST(CalibrationSpace, TheSeatSpaceAddsTheUnmeasuredSeatsParticipationsAtTheirPriorZero) {
  // paper-2mw measures b5 (point1) and b3 (point2): b4 and b6 are the parallel-stage bearings
  // without a sensor, so default_space(d, true) adds their participation per point (2 × 2 = 4)
  // to the standard 66; each linear, prior the description's 0, σ 0.5, ±1, and setting one
  // sets that point's three modes at that seat, and nothing else.
  const model::Drivetrain d = model::paper_2mw();
  EXPECT_EQ(model::calibration::default_space(d).size(), 66u);
  const CalibrationSpace space = model::calibration::default_space(d, true);
  ASSERT_EQ(space.size(), 70u);
  std::size_t seats = 0;
  for (std::size_t i = 0; i < space.size(); ++i) {
    const auto& v = space.variable(i);
    if (v.field != model::calibration::ParameterField::kHousingSeat) continue;
    ++seats;
    const std::size_t bearing = v.index / 6 + model::kHousingSeatFirstBearing + 1;
    EXPECT_TRUE(bearing == 4 || bearing == 6) << space.name(i);
    EXPECT_FALSE(v.logarithmic);
    EXPECT_EQ(v.prior_sd, 0.5);
    EXPECT_EQ(v.lower, -1.0);
    EXPECT_EQ(v.upper, 1.0);
    EXPECT_EQ(CalibrationSpace::get(space.prior(), v), 0.0);
    EXPECT_EQ(space.whiten(i, 0.0), 0.0);
    model::DynamicsParameters p = space.prior();
    CalibrationSpace::set(p, v, 0.4);
    for (std::size_t k = 0; k < p.housing_seat_participation.size(); ++k) {
      const bool tied = k >= v.index && k < v.index + model::kHousingModesPerPoint;
      EXPECT_EQ(p.housing_seat_participation[k], tied ? 0.4 : 0.0) << space.name(i) << " " << k;
    }
  }
  EXPECT_EQ(seats, 4u);
}

TEST_F(CalibratorTest,
       AnOffNominalRecordingTriggersCalibrationAndTheChosenParametersFitBothPoints) {
  // Arrange
  auto cal = make(CalibrationMethod::kImprovedMogoa, 8, 8);
  PointIndicators before{};
  ASSERT_TRUE(cal->evaluate(nominal_parameters(), before));
  ASSERT_TRUE(needs_calibration(before));
  CalibrationResult none;
  EXPECT_FALSE(cal->read_result(none));
  // Act
  ASSERT_TRUE(cal->start(nominal_parameters()));
  StepStatus s;
  while ((s = cal->step()) == StepStatus::kRunning) {
  }
  // Assert
  EXPECT_EQ(s, StepStatus::kFinished);
  CalibrationResult r;
  ASSERT_TRUE(cal->read_result(r));
  EXPECT_EQ(r.generation, 1u);
  EXPECT_TRUE(r.finished);
  EXPECT_TRUE(r.fits);
  for (const Indicators& i : r.indicators) {
    EXPECT_LE(i.f1, kF1Threshold);
    EXPECT_LE(i.f2, kF2Threshold);
    EXPECT_LE(i.f3, kF3Threshold);
  }
  EXPECT_GT(r.evaluations_to_threshold, 0u);
  EXPECT_EQ(r.evaluations, 8u * 9u);
}

TEST_F(CalibratorTest, PublishedMogoaIsSelectableAndDeterministicUnderASeed) {
  auto run = [&](std::uint64_t seed) {
    auto cal = make(CalibrationMethod::kPublishedMogoa, 8, 4, seed);
    cal->start(nominal_parameters());
    while (cal->step() == StepStatus::kRunning) {
    }
    CalibrationResult r;
    EXPECT_TRUE(cal->read_result(r));
    return r;
  };
  const CalibrationResult a = run(11);
  const CalibrationResult b = run(11);
  const CalibrationResult c = run(12);
  EXPECT_EQ(a.evaluations, 8u * 5u);
  EXPECT_EQ(a.parameters.rayleigh_eta, b.parameters.rayleigh_eta);
  EXPECT_EQ(a.parameters.mesh_stiffness_scale, b.parameters.mesh_stiffness_scale);
  EXPECT_EQ(a.indicators[0].f3, b.indicators[0].f3);
  EXPECT_NE(a.parameters.rayleigh_eta, c.parameters.rayleigh_eta);
}

TEST_F(CalibratorTest, CancelStopsAtTheNextStepAndPublishesACancelledResult) {
  auto cal = make(CalibrationMethod::kImprovedMogoa, 8, 50);
  cal->start(nominal_parameters());
  ASSERT_EQ(cal->step(), StepStatus::kRunning);  // initial population
  ASSERT_EQ(cal->step(), StepStatus::kRunning);  // iteration 1
  cal->cancel();
  EXPECT_EQ(cal->step(), StepStatus::kCancelled);
  EXPECT_EQ(cal->step(), StepStatus::kCancelled);
  CalibrationResult r;
  ASSERT_TRUE(cal->read_result(r));
  EXPECT_TRUE(r.cancelled);
  EXPECT_FALSE(r.finished);
  EXPECT_EQ(r.iterations, 1u);
  EXPECT_EQ(r.evaluations, 16u);
}

TEST_F(CalibratorTest, StepsDoNotAllocate) {
  auto cal = make(CalibrationMethod::kImprovedMogoa, 8, 3);
  ASSERT_TRUE(cal->start(nominal_parameters()));
  const std::size_t before = g_allocations.load();
  while (cal->step() == StepStatus::kRunning) {
  }
  EXPECT_EQ(g_allocations.load(), before);
}

// A torsional mode whose spring is the sun shaft (f_n = f_1·√s, s the stiffness scale) lifts
// the harmonics of a 13.745 Hz mesh through a single-degree-of-freedom response (ζ = 0.03):
// the residual of the harmonics' amplitudes against those at s_true, the quantity the
// placement lowers. It is not monotonic in s (each harmonic peaks as the mode crosses it).
double harmonics_residual(double s, double s_true) {
  const auto amplitude = [](double scale, int n) {
    const double r = 13.745 * n / (118.7 * std::sqrt(scale));
    return 1.0 / std::sqrt((1 - r * r) * (1 - r * r) + (0.06 * r) * (0.06 * r));
  };
  double num = 0.0, den = 0.0;
  for (int n = 1; n <= 20; ++n) {
    const double a = amplitude(s, n), b = amplitude(s_true, n);
    num += (a - b) * (a - b);
    den += b * b;
  }
  return std::sqrt(num / den);
}

TEST(ResonancePlacement, AModeFarFromTheRecordingsIsScannedAndRefittedAtTheNearestGridPoint) {
  // Arrange: the recording's mode at s = 3 (206 Hz), the fit at the prior's (1: 118.7 Hz),
  // where a step of +10 % raises the residual: no local step finds it.
  const DynamicsParameters prior = model::paper_2mw().dynamics;
  DynamicsParameters fitted = prior;
  fitted.rayleigh_eta = 7.0;  // a fitted value of another parameter, to be kept
  std::size_t calls = 0;
  const auto residual = [&](const DynamicsParameters& p) {
    ++calls;
    EXPECT_EQ(p.rayleigh_eta, 7.0);  // only the scanned parameter moves
    return harmonics_residual(p.sun_shaft_torsion_scale, 3.0);
  };
  EXPECT_GT(harmonics_residual(1.1, 3.0), harmonics_residual(1.0, 3.0));

  // Act
  const PlacementScan scan = scan_placement(prior, fitted, 0.25, residual);

  // Assert: nine log-centres of equal intervals of 1/9 … 9, ×81^(1/9) apart, 1 among them,
  // neither bound; the lowest residual at 9^(4/9) = 2.655, the grid point nearest 3, lower
  // than the fit's by more than the threshold: a refit from there. The fit sits on the grid
  // point 1: simulated once, as the fit, not again as a grid point.
  EXPECT_EQ(calls, kPlacementPoints);
  EXPECT_NEAR(scan.value.front(), std::pow(9.0, -8.0 / 9.0), 1e-12);
  EXPECT_NEAR(scan.value.back(), std::pow(9.0, 8.0 / 9.0), 1e-9);
  EXPECT_NEAR(scan.value[4], 1.0, 1e-12);
  EXPECT_NEAR(scan.value[1] / scan.value[0], std::pow(81.0, 1.0 / 9.0), 1e-9);
  EXPECT_NEAR(scan.best, std::pow(9.0, 4.0 / 9.0), 1e-9);
  EXPECT_LT(scan.best_residual, scan.fitted_residual - 0.25);
  EXPECT_TRUE(scan.refit);
}

TEST(ResonancePlacement, TheGridFollowsTheDescriptionsPrior) {
  DynamicsParameters prior = model::paper_2mw().dynamics;
  prior.sun_shaft_torsion_scale = 2.0;
  const PlacementScan scan =
      scan_placement(prior, prior, 0.25, [](const DynamicsParameters&) { return 1.0; });
  EXPECT_NEAR(scan.value[4], 2.0, 1e-12);
  EXPECT_NEAR(scan.value.front(), 2.0 * std::pow(9.0, -8.0 / 9.0), 1e-12);
  EXPECT_FALSE(scan.refit);  // a flat residual: nothing to place
  EXPECT_EQ(scan.best, 2.0);
}

TEST(ResonancePlacement, AModeWhereTheRecordingHasItIsLeftThere) {
  const DynamicsParameters prior = model::paper_2mw().dynamics;
  const auto residual = [](const DynamicsParameters& p) {
    return harmonics_residual(p.sun_shaft_torsion_scale, 1.0);
  };
  const PlacementScan scan = scan_placement(prior, prior, 0.25, residual);
  EXPECT_FALSE(scan.refit);
  EXPECT_EQ(scan.best, 1.0);
  EXPECT_EQ(scan.best_residual, 0.0);
}

TEST(ResonancePlacement, WithNoThresholdAnyLowerGridPointRefitsAndTheFitsOwnPointNever) {
  // The command's threshold is 0: a refit wherever another grid point is lower at all. A fit
  // off the grid (a released refit's 4.85) is compared with all nine points, each simulated.
  const DynamicsParameters prior = model::paper_2mw().dynamics;
  DynamicsParameters fitted = prior;
  fitted.sun_shaft_torsion_scale = 4.85;
  std::size_t calls = 0;
  const auto toward_3 = [&](const DynamicsParameters& p) {
    ++calls;
    return std::abs(std::log(p.sun_shaft_torsion_scale / 3.0));  // lowest at 3, V-shaped
  };
  const PlacementScan off = scan_placement(prior, fitted, 0.0, toward_3);
  EXPECT_EQ(calls, kPlacementPoints + 1);
  EXPECT_NEAR(off.best, std::pow(9.0, 4.0 / 9.0), 1e-9);  // 2.655: |ln(2.655/3)| < |ln(4.85/3)|
  EXPECT_TRUE(off.refit);
  // At the prior, with the residual lowest there: nothing lower, no refit, however small the
  // threshold (its own grid point is not a second, rounding-different sample of it).
  const auto at_1 = [](const DynamicsParameters& p) {
    return 0.07 + std::abs(std::log(p.sun_shaft_torsion_scale));
  };
  const PlacementScan on = scan_placement(prior, prior, 0.0, at_1);
  EXPECT_FALSE(on.refit);
  EXPECT_EQ(on.best, 1.0);
  EXPECT_EQ(on.best_residual, on.fitted_residual);
}

TEST(CalibrationSpace, TheSunShaftTorsionIsReleasedOnlyOnRequestCentredOnTheDescription) {
  // Arrange: a description whose sun shaft is already twice the model's default.
  model::Drivetrain d = model::paper_2mw();
  d.dynamics.sun_shaft_torsion_scale = 2.0;
  const CalibrationSpace standard = model::calibration::default_space(d);
  const auto index_of_sun = [](const CalibrationSpace& s) {
    for (std::size_t i = 0; i < s.size(); ++i)
      if (s.variable(i).field == model::calibration::ParameterField::kSunShaftTorsion) return i;
    return s.size();
  };
  ASSERT_EQ(index_of_sun(standard), standard.size());  // not in the standard space

  // Act
  const CalibrationSpace released = standard.with_sun_shaft_torsion();

  // Assert: one variable more, the others as they were; ln, σ = ln 3, ×/÷ 9 about 2.
  ASSERT_EQ(released.size(), standard.size() + 1);
  EXPECT_EQ(released.overflow(), 0u);
  for (std::size_t i = 0; i < standard.size(); ++i)
    EXPECT_STREQ(released.name(i), standard.name(i));
  const std::size_t k = index_of_sun(released);
  ASSERT_EQ(k, standard.size());
  const auto& v = released.variable(k);
  EXPECT_STREQ(released.name(k), "sun_shaft_torsion_scale");
  EXPECT_TRUE(v.logarithmic);
  EXPECT_NEAR(v.prior_sd, std::log(3.0), 1e-15);
  EXPECT_NEAR(v.lower, 2.0 / 9.0, 1e-15);
  EXPECT_NEAR(v.upper, 18.0, 1e-12);
  EXPECT_NEAR(released.whiten(k, 2.0), 0.0, 1e-12);
  EXPECT_NEAR(released.whiten(k, 6.0), 1.0, 1e-12);  // one prior σ: ×3
  // Setting it moves the sun shaft and nothing else.
  std::array<double, model::calibration::kMaxCalibrationVariables> z{};
  z[k] = -1.0;
  const DynamicsParameters p = released.to_parameters(z.data());
  EXPECT_NEAR(p.sun_shaft_torsion_scale, 2.0 / 3.0, 1e-12);
  std::array<double, model::calibration::kMaxCalibrationVariables> zp{}, zq{};
  standard.to_variables(p, zp.data());
  standard.to_variables(released.prior(), zq.data());
  for (std::size_t i = 0; i < standard.size(); ++i) EXPECT_EQ(zp[i], zq[i]) << standard.name(i);
  // Released twice is released once.
  EXPECT_EQ(released.with_sun_shaft_torsion().size(), released.size());
}

TEST(ResonancePlacement, TheFitThatCalibratesIsKeptThenTheLowerResidualThenTheLowerWorstIndicator) {
  EXPECT_TRUE(keep_refit(false, 0.5, 1.2, true, 0.9, 0.8));   // only the refit calibrates
  EXPECT_FALSE(keep_refit(true, 0.9, 0.8, false, 0.2, 1.1));  // only the first does
  EXPECT_TRUE(keep_refit(true, 0.9, 0.8, true, 0.3, 0.9));    // both: the lower residual
  EXPECT_FALSE(keep_refit(true, 0.3, 0.8, true, 0.9, 0.5));
  EXPECT_TRUE(keep_refit(false, 0.3, 1.5, false, 0.9, 1.2));  // neither: the lower worst
  EXPECT_FALSE(keep_refit(false, 0.9, 1.2, false, 0.3, 1.5));
}

}  // namespace
