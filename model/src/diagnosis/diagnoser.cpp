#include "model/diagnosis/diagnoser.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <optional>

#include "model/calibration/dynamics_simulator.hpp"
#include "model/calibration/lumped_simulator.hpp"
#include "model/calibration/trust_region.hpp"
#include "model/dsp/order_tracking.hpp"
#include "model/dsp/spectrum.hpp"

namespace model::diagnosis {

const char* to_string(DiagnosisStatus status) {
  switch (status) {
    case DiagnosisStatus::kOk:
      return "ok";
    case DiagnosisStatus::kBadInput:
      return "bad input";
    case DiagnosisStatus::kTooShort:
      return "recording too short for the analysis";
    case DiagnosisStatus::kNoSpeed:
      return "no usable speed reference";
    case DiagnosisStatus::kSimulationFailed:
      return "the dynamics model could not be simulated";
    case DiagnosisStatus::kCancelled:
      return "cancelled";
  }
  return "unknown";
}

namespace {

using Spectra = std::array<ChannelAnalysis, kPoints>;

// Share of the recorded order-spectrum energy up to max_hz (both points) that the
// simulation does not explain: Σ(a_m − a_s)² / Σ a_m² over lines 1..K, not clipped: above 1
// where the simulation puts more energy where the recording has none than it explains.
double spectral_share(const Spectra& rec, const Spectra& sim, double max_hz) {
  double miss = 0.0, total = 0.0;
  for (std::size_t p = 0; p < kPoints; ++p) {
    const OrderSpectrum& m = rec[p].spectrum;
    const OrderSpectrum& s = sim[p].spectrum;
    if (m.amplitude.empty() || m.revolutions != s.revolutions) return 1.0;
    const auto last =
        static_cast<std::size_t>(max_hz / m.shaft_hz * static_cast<double>(m.revolutions));
    dsp::add_unexplained_energy(m.amplitude.data(), m.amplitude.size(), s.amplitude.data(),
                                s.amplitude.size(), last, miss, total);
  }
  return total > 0.0 ? miss / total : 1.0;
}

// The report's residual (shared/reference/diagnosis-report.md "residual"; the same sum as
// `drivetwin calibrate`): the share clipped to [0, 1].
double spectral_residual(const Spectra& rec, const Spectra& sim, double max_hz) {
  return std::clamp(spectral_share(rec, sim, max_hz), 0.0, 1.0);
}

// The same share in power per 1/12-octave band (analysis.hpp add_band_residual): what a
// model of a non-periodic excitation (impacts with slip) can match. Not clipped.
double band_share(const Spectra& rec, const Spectra& sim, double max_hz) {
  double miss = 0.0, total = 0.0;
  for (std::size_t p = 0; p < kPoints; ++p) {
    const OrderSpectrum& m = rec[p].spectrum;
    if (m.amplitude.empty() || m.revolutions != sim[p].spectrum.revolutions) return 1.0;
    const auto last =
        static_cast<std::size_t>(max_hz / m.shaft_hz * static_cast<double>(m.revolutions));
    add_band_residual(m, sim[p].spectrum, last, miss, total);
  }
  return total > 0.0 ? miss / total : 1.0;
}

// The same sum over the lines of `windows` only (per point, line indices of the
// recording's spectrum in the given domain). In the envelope (an impact train with slip:
// its lines wander and broaden by a few lines where the periodic model's stay put) each
// run of adjacent window lines is compared in power (analysis.hpp add_window_residual).
double signature_residual(const Spectra& rec, const Spectra& sim, Domain domain, bool train,
                          const std::array<std::vector<std::size_t>, kPoints>& windows) {
  double miss = 0.0, total = 0.0;
  const bool env = domain == Domain::kEnvelope;
  for (std::size_t p = 0; p < kPoints; ++p) {
    const OrderSpectrum& m = env ? rec[p].envelope : rec[p].spectrum;
    const OrderSpectrum& s = env ? sim[p].envelope : sim[p].spectrum;
    if (train) {
      add_window_residual(m, s, windows[p], miss, total);
      continue;
    }
    for (std::size_t k : windows[p]) {
      if (k >= m.amplitude.size()) continue;
      const double a_s = k < s.amplitude.size() ? s.amplitude[k] : 0.0;
      const double d = m.amplitude[k] - a_s;
      miss += d * d;
      total += m.amplitude[k] * m.amplitude[k];
    }
  }
  return total > 0.0 ? std::clamp(miss / total, 0.0, 1.0) : 1.0;
}

SpectrumTrace trace(const OrderSpectrum& s, double ref_hz, double max_hz, std::size_t points) {
  SpectrumTrace t;
  if (s.amplitude.empty() || points == 0) return t;
  const double r = static_cast<double>(s.revolutions);
  const double bin_hz = max_hz / static_cast<double>(points);
  t.hz.resize(points);
  t.amplitude.assign(points, 0.0);
  for (std::size_t i = 0; i < points; ++i) t.hz[i] = (static_cast<double>(i) + 0.5) * bin_hz;
  for (std::size_t k = 1; k < s.amplitude.size(); ++k) {
    const double hz = static_cast<double>(k) / r * ref_hz;
    if (hz >= max_hz) break;
    const auto i = static_cast<std::size_t>(hz / bin_hz);
    t.amplitude[i] = std::max(t.amplitude[i], s.amplitude[k]);
  }
  return t;
}

// Whether `order` lies within 2 lines (of an r-revolution spectrum) of one of `orders` — the
// envelope's synchronous comb, where locate reads no bearing line (locate.hpp).
bool near_any(double order, double r, const std::vector<double>& orders) {
  for (double o : orders)
    if (std::abs(order - o) * r <= 2.0) return true;
  return false;
}

}  // namespace

// Named, not file-local: Diagnoser::Work holds them (-Wsubobject-linkage once this file
// shares the library's unity TU, docs/ci.md).
namespace diagnoser_detail {
// The line set a hypothesis is fitted and judged on.
struct FitLine {
  std::size_t point = 0;
  Domain domain = Domain::kSpectrum;
  double order = 0.0;      // where the recording has it
  double tolerance = 0.0;  // search in the simulation
  double measured = 0.0;
  double noise = 0.0;
  double weight = 1.0;
};
}  // namespace diagnoser_detail
using diagnoser_detail::FitLine;

struct Diagnoser::Work {
  DiagnosisInput input;
  AngleMap map;
  double ref_hz = 0.0;
  AnalysisWindow full, half_a, half_b;
  calibration::OperatingPoint op;
  double env_order = 0.0;
  double sim_fs = 0.0;
  std::size_t sim_spr = 0;
  Spectra rec_full, rec_a, rec_b;
  std::array<dsp::PointFeatures, kPoints> measured{};
  std::unique_ptr<EffectCalibrationAdapter> adapter;
  std::unique_ptr<calibration::Calibrator> calibrator;
  bool calibrating = false;
  int simulate_phase = 0;
  Spectra sim_before, sim_cal, sim_cal_half;
  std::vector<ChannelPair> pairs;
  LocateResult located;
  // Refit of the current candidate.
  std::size_t candidate = 0;
  std::vector<EffectParameter> params;
  std::vector<FitLine> lines;
  std::unique_ptr<calibration::FeatureMap> map_impl;
  std::unique_ptr<calibration::TrustRegionLeastSquares> tr;
  bool holdout_pending = false;
  std::size_t fit_revs = 0;
};

namespace {

// The effect fit's view for the trust region: x (effect parameters in search
// coordinates) → φ = (ln √(s² + n²) of every fit line, ln RMS of each point).
class EffectFitMap : public calibration::FeatureMap {
 public:
  EffectFitMap(EffectSimulator& sim, const Catalogue& cat, const Hypothesis& h,
               const std::vector<EffectParameter>& params, const std::vector<FitLine>& lines,
               const DynamicsParameters& calibrated, const calibration::OperatingPoint& op,
               double fs, double ref_hz, std::size_t revs, const AnalysisConfig& acfg,
               const ChannelAnalysis* bands, double env_order, double measured_rate,
               std::size_t& simulations)
      : sim_(sim),
        cat_(cat),
        h_(h),
        params_(params),
        lines_(lines),
        calibrated_(calibrated),
        op_(op),
        fs_(fs),
        ref_hz_(ref_hz),
        revs_(revs),
        acfg_(acfg),
        bands_(bands),
        env_order_(env_order),
        measured_rate_(measured_rate),
        simulations_(simulations) {}
  std::size_t variables() const override { return params_.size(); }
  std::size_t features() const override { return lines_.size() + kPoints; }
  double lower(std::size_t i) const override { return to_search(i, params_[i].lower); }
  double upper(std::size_t i) const override { return to_search(i, params_[i].upper); }
  double to_search(std::size_t i, double v) const {
    return params_[i].log_scale ? std::log(std::max(v, 1e-300))
                                : v / (params_[i].upper - params_[i].lower);
  }
  double from_search(std::size_t i, double x) const {
    return params_[i].log_scale ? std::exp(x) : x * (params_[i].upper - params_[i].lower);
  }
  EffectSetting setting(const double* x) const {
    EffectSetting s;
    s.hypothesis = &h_;
    for (std::size_t i = 0; i < params_.size() && i < kMaxEffectParameters; ++i)
      s.values[i] = from_search(i, x[i]);
    s.measured_rate_order = measured_rate_;
    return s;
  }
  bool evaluate(const double* x, double* phi) override {
    std::array<calibration::WaveformView, kPoints> w{};
    ++simulations_;
    const double seconds = (static_cast<double>(revs_) + 2.5) / ref_hz_;
    if (!sim_.simulate(calibrated_, {setting(x)}, op_, fs_, seconds, w)) return false;
    AnalysisConfig a = acfg_;
    a.synchronous_averages = false;
    const AngleMap map = AngleMap::constant(ref_hz_);
    const bool env = h_.domain == Domain::kEnvelope;
    for (std::size_t p = 0; p < kPoints; ++p) {
      ChannelAnalysis an;
      if (!analyse_channel(w[p].samples, w[p].count, w[p].sample_rate_hz, map, {1.0, revs_}, cat_,
                           a, env_order_, &bands_[p].band, an, &bands_[p].whitening))
        return false;
      const OrderSpectrum& s = env ? an.envelope : an.spectrum;
      for (std::size_t i = 0; i < lines_.size(); ++i) {
        const FitLine& l = lines_[i];
        if (l.point != p) continue;
        double a_s = s.tone(l.order);
        if (l.tolerance > 0.0) {
          const double r = static_cast<double>(s.revolutions);
          for (long long k = static_cast<long long>(std::floor(l.order * (1.0 - l.tolerance) * r));
               k <= static_cast<long long>(std::ceil(l.order * (1.0 + l.tolerance) * r)); ++k)
            if (k > 0 && !(excl_ != nullptr && near_any(static_cast<double>(k) / r, r, *excl_)))
              a_s = std::max(a_s, s.tone(static_cast<double>(k) / r));
        }
        phi[i] = 0.5 * std::log(a_s * a_s + l.noise * l.noise);
      }
      phi[lines_.size() + p] = std::log(std::max(an.stats.rms, 1e-300));
    }
    return true;
  }

 private:
  EffectSimulator& sim_;
  const Catalogue& cat_;
  const Hypothesis& h_;
  const std::vector<EffectParameter>& params_;
  const std::vector<FitLine>& lines_;
  DynamicsParameters calibrated_;
  calibration::OperatingPoint op_;
  double fs_, ref_hz_;
  std::size_t revs_;
  AnalysisConfig acfg_;
  const ChannelAnalysis* bands_;  // the recording's whole-record analyses: band and filter
  double env_order_, measured_rate_;
  std::size_t& simulations_;
  std::vector<double> sync_ = envelope_exclusions(cat_);  // never read a bearing line there
  std::vector<double> gears_ = spectrum_exclusions(cat_);
  const std::vector<double>* excl_ = bearing_exclusions(h_, sync_, gears_);
};

}  // namespace

Diagnoser::Diagnoser(const Drivetrain& drivetrain, EffectSimulator& simulator,
                     const DiagnoserConfig& config)
    : drivetrain_(drivetrain), simulator_(simulator), config_(config) {
  std::vector<std::string> sensors;
  for (const MeasurementPoint& m : drivetrain.measurement_points) sensors.push_back(m.location);
  CatalogueConfig cc = config_.catalogue;
  catalogue_ = build_catalogue(drivetrain, sensors, cc);
}

Diagnoser::~Diagnoser() = default;

void Diagnoser::start(const DiagnosisInput& input) {
  work_ = std::make_unique<Work>();
  work_->input = input;
  report_ = DiagnosisReport{};
  report_.drivetrain = drivetrain_.name;
  report_.reference_shaft = catalogue_.reference_shaft;
  cancel_requested_ = false;
  stepped_ = false;
  simulations_ = 0;
  stage_ = DiagnosisStage::kSpeed;
}

DiagnosisStep Diagnoser::fail(DiagnosisStatus status, std::string message) {
  report_.status = status;
  report_.message = std::move(message);
  stage_ = DiagnosisStage::kDone;
  publish();
  return status == DiagnosisStatus::kCancelled ? DiagnosisStep::kCancelled : DiagnosisStep::kFailed;
}

DiagnosisStep Diagnoser::finish() {
  stage_ = DiagnosisStage::kDone;
  publish();
  return DiagnosisStep::kFinished;
}

void Diagnoser::publish() {
  DiagnosisSummary s;
  s.generation = ++generation_;
  stepped_ = true;
  s.finished = stage_ == DiagnosisStage::kDone;
  s.cancelled = report_.status == DiagnosisStatus::kCancelled;
  s.status = report_.status;
  s.stage = stage_;
  s.fit_before = report_.fit_before;
  s.fit_calibrated = report_.fit_calibrated;
  s.fit_after = report_.fit_after;
  s.residual_before = report_.residual_before;
  s.residual_calibrated = report_.residual_calibrated;
  s.residual_after = report_.residual_after;
  s.calibrated = report_.parameters_calibrated;
  for (std::size_t i : report_.missing) {
    if (s.reported == DiagnosisSummary::kMaxReported) break;
    const CandidateResult& c = report_.candidates[i];
    DiagnosisSummary::Entry& e = s.effects[s.reported++];
    e.effect = c.effect;
    std::snprintf(e.location.data(), e.location.size(), "%s", c.location.c_str());
    e.confidence = c.confidence;
    for (std::size_t k = 0; k < c.parameters.size() && k < kMaxEffectParameters; ++k)
      e.parameters[k] = c.parameters[k].second;
  }
  summary_ = s;
}

DiagnosisStep Diagnoser::step() {
  if (stage_ == DiagnosisStage::kIdle) return DiagnosisStep::kIdle;
  if (stage_ == DiagnosisStage::kDone)
    return report_.status == DiagnosisStatus::kOk ? DiagnosisStep::kFinished
                                                  : DiagnosisStep::kFailed;
  if (cancel_requested_) return fail(DiagnosisStatus::kCancelled, "cancelled");
  switch (stage_) {
    case DiagnosisStage::kSpeed:
      if (!step_speed()) return DiagnosisStep::kFailed;
      stage_ = DiagnosisStage::kAnalyse;
      break;
    case DiagnosisStage::kAnalyse:
      if (!step_analyse()) return DiagnosisStep::kFailed;
      stage_ = DiagnosisStage::kCalibrate;
      break;
    case DiagnosisStage::kCalibrate:
      if (!step_calibrate()) return DiagnosisStep::kFailed;
      break;
    case DiagnosisStage::kSimulate:
      if (!step_simulate()) return DiagnosisStep::kFailed;
      break;
    case DiagnosisStage::kLocate:
      step_locate();
      stage_ = DiagnosisStage::kRefit;
      break;
    case DiagnosisStage::kRefit:
      if (!step_refit()) return DiagnosisStep::kFailed;
      break;
    case DiagnosisStage::kDecide:
      step_decide();
      stage_ = DiagnosisStage::kFinal;
      break;
    case DiagnosisStage::kFinal:
      if (!step_final()) return DiagnosisStep::kFailed;
      return finish();
    case DiagnosisStage::kIdle:
    case DiagnosisStage::kDone:
      break;
  }
  publish();
  return DiagnosisStep::kRunning;
}

bool Diagnoser::step_speed() {
  Work& w = *work_;
  const DiagnosisInput& in = w.input;
  if (!(in.sample_rate_hz > 0.0) || in.samples < 16) {
    fail(DiagnosisStatus::kBadInput, "sample rate must be > 0 and the recording hold samples");
    return false;
  }
  for (std::size_t p = 0; p < kPoints; ++p) {
    if (in.points[p] == nullptr) {
      fail(DiagnosisStatus::kBadInput,
           "measurement point " + std::to_string(p + 1) + " has no channel");
      return false;
    }
    const dsp::DspStatus q =
        dsp::check_waveform(in.points[p], in.samples, config_.features.flat_threshold);
    if (q != dsp::DspStatus::kOk) {
      fail(DiagnosisStatus::kBadInput,
           std::string("measurement point ") + std::to_string(p + 1) + ": " + dsp::to_string(q));
      return false;
    }
  }
  const double fs = in.sample_rate_hz;
  const double nominal = catalogue_.reference_hz(in.rotor_speed_rpm);
  if (in.tacho_pulses_s.size() >= 2) {
    const PartRate* shaft = in.tacho_shaft.empty() ? nullptr : catalogue_.shaft(in.tacho_shaft);
    if (!in.tacho_shaft.empty() && shaft == nullptr) {
      fail(DiagnosisStatus::kNoSpeed,
           "tacho on '" + in.tacho_shaft + "', which is not a shaft of the drivetrain");
      return false;
    }
    const AngleMap tacho = AngleMap::from_pulses(in.tacho_pulses_s);
    if (!tacho.valid()) {
      fail(DiagnosisStatus::kNoSpeed, "tacho pulse times are not increasing");
      return false;
    }
    if (shaft == nullptr || shaft->id == catalogue_.reference_shaft) {
      w.map = tacho;
    } else {
      // Reference revolution k at tacho angle k·order.
      std::vector<double> pulses;
      const double first = std::ceil(tacho.revolutions_at(0.0) / shaft->order);
      const double last = tacho.revolutions_at(static_cast<double>(in.samples) / fs) / shaft->order;
      for (double k = first; k <= last; k += 1.0) pulses.push_back(tacho.time_at(k * shaft->order));
      w.map = AngleMap::from_pulses(std::move(pulses));
    }
    report_.speed_source = "tacho";
  } else {
    std::vector<LineCandidate> cands;
    for (std::size_t i = 0; i < catalogue_.meshes.size() && i < drivetrain_.stages.size(); ++i) {
      const GearStage& st = drivetrain_.stages[i];
      double spacing = 1e300;
      for (const std::string& id : {st.input_shaft, st.output_shaft})
        if (const PartRate* s = catalogue_.shaft(id)) spacing = std::min(spacing, s->order);
      if (st.type == StageType::kPlanetary)
        if (const PartRate* pl = catalogue_.shaft("planet")) spacing = std::min(spacing, pl->order);
      for (int h = 1; h <= 3; ++h) cands.push_back({h * catalogue_.meshes[i].order, spacing});
    }
    TrackedSpeed t;
    if (nominal > 0.0) t = track_speed(in.points[0], in.samples, fs, nominal, cands, config_.speed);
    if (t.ok) {
      w.map = std::move(t.map);
      report_.speed_source = "mesh line";
    } else if (nominal > 0.0) {
      w.map = AngleMap::constant(nominal);
      report_.speed_source = "operating point";
    } else {
      fail(DiagnosisStatus::kNoSpeed, "no tacho, no trackable mesh line and no rotor speed");
      return false;
    }
  }
  w.ref_hz = w.map.mean_hz();
  const double start = std::ceil(w.map.revolutions_at(2.0 / fs)) + 1.0;
  const std::size_t avail = revolutions_available(in.samples, fs, w.map, 1.0, start);
  const std::size_t half = fft_size_at_most(avail / 2);
  if (half < config_.min_revolutions / 2 || avail < config_.features.revolutions + 2) {
    char text[200];
    std::snprintf(
        text, sizeof text,
        "the recording covers %zu revolutions of the %s; the analysis needs %zu (%.1f s at %.2f "
        "Hz)",
        avail, catalogue_.reference_shaft.c_str(),
        std::max(config_.min_revolutions, config_.features.revolutions + 2),
        static_cast<double>(std::max(config_.min_revolutions, config_.features.revolutions + 2)) /
            w.ref_hz,
        w.ref_hz);
    fail(DiagnosisStatus::kTooShort, text);
    return false;
  }
  w.full = {start, fft_size_at_most(avail)};
  w.half_a = {start, half};
  w.half_b = {start + static_cast<double>(avail / 2), half};
  // Speed range over the recording.
  const auto& p = w.map.pulses();
  report_.speed_min_hz = 1e300;
  for (std::size_t i = 1; i < p.size(); ++i) {
    report_.speed_min_hz = std::min(report_.speed_min_hz, 1.0 / (p[i] - p[i - 1]));
    report_.speed_max_hz = std::max(report_.speed_max_hz, 1.0 / (p[i] - p[i - 1]));
  }
  report_.reference_hz = w.ref_hz;
  report_.revolutions = w.full.revs;
  report_.half_revolutions = half;
  report_.rotor_speed_rpm = w.ref_hz / catalogue_.reference_per_rotor * 60.0;
  report_.input_torque_nm = in.input_torque_nm;
  w.op = {report_.rotor_speed_rpm, in.input_torque_nm};
  // The simulation's rate: a power of two samples per reference revolution covering the
  // analysis band 2.2 times, so a simulated waveform is already angle-sampled.
  w.sim_spr = std::bit_ceil(
      static_cast<std::size_t>(std::ceil(2.2 * config_.analysis.max_frequency_hz / w.ref_hz)));
  w.sim_fs = static_cast<double>(w.sim_spr) * w.ref_hz;
  w.env_order = envelope_max_order(catalogue_);
  return true;
}

bool Diagnoser::step_analyse() {
  Work& w = *work_;
  const DiagnosisInput& in = w.input;
  AnalysisConfig a = config_.analysis;
  a.band_max_hz = 0.45 * w.sim_fs;  // bands the simulation can also show
  for (std::size_t p = 0; p < kPoints; ++p) {
    if (!analyse_channel(in.points[p], in.samples, in.sample_rate_hz, w.map, w.full, catalogue_, a,
                         w.env_order, nullptr, w.rec_full[p]) ||
        !analyse_channel(in.points[p], in.samples, in.sample_rate_hz, w.map, w.half_a, catalogue_,
                         a, w.env_order, &w.rec_full[p].band, w.rec_a[p]) ||
        !analyse_channel(in.points[p], in.samples, in.sample_rate_hz, w.map, w.half_b, catalogue_,
                         a, w.env_order, &w.rec_full[p].band, w.rec_b[p])) {
      fail(DiagnosisStatus::kTooShort,
           "measurement point " + std::to_string(p + 1) + ": the analysis window does not fit");
      return false;
    }
  }
  // The calibrator and its measured features.
  const double top_hz = catalogue_.meshes.empty()
                            ? 1000.0
                            : catalogue_.meshes.back().order * w.ref_hz *
                                  static_cast<double>(config_.features.harmonics);
  w.adapter = std::make_unique<EffectCalibrationAdapter>(simulator_,
                                                         calibration::rom_sample_rate_hz(top_hz));
  // The calibration `drivetwin calibrate` runs (calibrator.hpp default_space: the standard
  // space with identification, priors and its rounds) unless the configuration names one.
  const calibration::CalibratorConfig& cc = config_.calibration;
  w.calibrator =
      std::make_unique<calibration::Calibrator>(*w.adapter, drivetrain_, config_.features, cc);
  if (w.calibrator->status() != dsp::DspStatus::kOk) {
    fail(DiagnosisStatus::kBadInput,
         std::string("calibration features: ") + dsp::to_string(w.calibrator->status()));
    return false;
  }
  dsp::FeatureExtractor fx(w.calibrator->feature_config());
  const dsp::SpeedReference ref{w.map.pulses().data(), w.map.pulses().size(), w.ref_hz};
  for (std::size_t p = 0; p < kPoints; ++p) {
    const dsp::DspStatus s =
        fx.extract(in.points[p], in.samples, in.sample_rate_hz, ref, w.measured[p]);
    if (s != dsp::DspStatus::kOk) {
      fail(s == dsp::DspStatus::kTooShort ? DiagnosisStatus::kTooShort : DiagnosisStatus::kBadInput,
           "measurement point " + std::to_string(p + 1) + ": " + dsp::to_string(s));
      return false;
    }
    if (w.measured[p].resolved_count() < calibration::kMinTones) {
      fail(DiagnosisStatus::kBadInput,
           "measurement point " + std::to_string(p + 1) + ": only " +
               std::to_string(w.measured[p].resolved_count()) +
               " mesh harmonics stand out of the noise; the indicators need " +
               std::to_string(calibration::kMinTones));
      return false;
    }
  }
  w.calibrator->set_measurement(w.measured, w.op);
  return true;
}

bool Diagnoser::step_calibrate() {
  Work& w = *work_;
  if (!w.calibrating) {
    report_.parameters_before = calibration::with_nominal_damping(drivetrain_.dynamics);
    ++simulations_;
    if (!w.calibrator->evaluate(report_.parameters_before, report_.fit_before)) {
      fail(DiagnosisStatus::kSimulationFailed,
           "at the description's parameters: " + simulator_.error());
      return false;
    }
    w.calibrator->start(report_.parameters_before);
    w.calibrating = true;
    return true;
  }
  const calibration::StepStatus st = w.calibrator->step();
  if (st == calibration::StepStatus::kRunning) return true;
  calibration::CalibrationResult r;
  if (!w.calibrator->read_result(r)) {
    r.parameters = report_.parameters_before;
    r.indicators = report_.fit_before;
  }
  report_.parameters_calibrated = r.parameters;
  report_.fit_calibrated = r.indicators;
  report_.calibration_evaluations = r.evaluations;
  simulations_ += r.evaluations;
  stage_ = DiagnosisStage::kSimulate;
  return true;
}

namespace {
bool analyse_simulation(EffectSimulator& sim, const DynamicsParameters& params,
                        const std::vector<EffectSetting>& fx, const calibration::OperatingPoint& op,
                        double fs, double ref_hz, std::size_t revs, const Catalogue& cat,
                        const AnalysisConfig& a, double env_order, const Spectra& rec_bands,
                        std::size_t& simulations, Spectra* full, Spectra* half,
                        std::size_t half_revs) {
  std::array<calibration::WaveformView, kPoints> w{};
  ++simulations;
  if (!sim.simulate(params, fx, op, fs, (static_cast<double>(revs) + 2.5) / ref_hz, w))
    return false;
  const AngleMap map = AngleMap::constant(ref_hz);
  for (std::size_t p = 0; p < kPoints; ++p) {
    if (full &&
        !analyse_channel(w[p].samples, w[p].count, w[p].sample_rate_hz, map, {1.0, revs}, cat, a,
                         env_order, &rec_bands[p].band, (*full)[p], &rec_bands[p].whitening))
      return false;
    if (half &&
        !analyse_channel(w[p].samples, w[p].count, w[p].sample_rate_hz, map, {1.0, half_revs}, cat,
                         a, env_order, &rec_bands[p].band, (*half)[p], &rec_bands[p].whitening))
      return false;
  }
  return true;
}
}  // namespace

bool Diagnoser::step_simulate() {
  Work& w = *work_;
  AnalysisConfig a = config_.analysis;
  a.band_max_hz = 0.45 * w.sim_fs;
  if (w.simulate_phase == 0) {
    if (!analyse_simulation(simulator_, report_.parameters_before, {}, w.op, w.sim_fs, w.ref_hz,
                            w.full.revs, catalogue_, a, w.env_order, w.rec_full, simulations_,
                            &w.sim_before, nullptr, 0)) {
      fail(DiagnosisStatus::kSimulationFailed,
           "at the description's parameters: " + simulator_.error());
      return false;
    }
    report_.residual_before =
        spectral_residual(w.rec_full, w.sim_before, config_.analysis.max_frequency_hz);
    w.simulate_phase = 1;
    return true;
  }
  if (!analyse_simulation(simulator_, report_.parameters_calibrated, {}, w.op, w.sim_fs, w.ref_hz,
                          w.full.revs, catalogue_, a, w.env_order, w.rec_full, simulations_,
                          &w.sim_cal, &w.sim_cal_half, w.half_a.revs)) {
    fail(DiagnosisStatus::kSimulationFailed, "at the calibrated parameters: " + simulator_.error());
    return false;
  }
  report_.residual_calibrated =
      spectral_residual(w.rec_full, w.sim_cal, config_.analysis.max_frequency_hz);
  report_.fit_after = report_.fit_calibrated;
  report_.residual_after = report_.residual_calibrated;
  report_.parameters_after = report_.parameters_calibrated;
  stage_ = DiagnosisStage::kLocate;
  return true;
}

void Diagnoser::step_locate() {
  Work& w = *work_;
  w.pairs.clear();
  for (std::size_t p = 0; p < kPoints; ++p) {
    const MeasurementPoint* mp =
        p < drivetrain_.measurement_points.size() ? &drivetrain_.measurement_points[p] : nullptr;
    w.pairs.push_back({mp ? mp->channel : "point" + std::to_string(p + 1), mp ? mp->location : "",
                       &w.rec_full[p], &w.sim_cal[p]});
  }
  w.located = locate(catalogue_, w.pairs, config_.locate);
  report_.ranking.assign(w.located.ranking.begin(),
                         w.located.ranking.begin() + static_cast<long>(std::min<std::size_t>(
                                                         16, w.located.ranking.size())));
  // The mismatch: every feature with a share worth naming, largest first.
  std::vector<const ResidualFeature*> feats;
  for (const ResidualFeature& f : w.located.features)
    if (f.share >= 0.05 || f.domain == FeatureDomain::kAverage) feats.push_back(&f);
  std::sort(feats.begin(), feats.end(), [](const ResidualFeature* a, const ResidualFeature* b) {
    return a->share * a->max_snr > b->share * b->max_snr;
  });
  for (const ResidualFeature* f : feats) {
    MismatchEntry m;
    m.channel = w.pairs[f->channel].channel;
    m.domain = f->domain;
    m.band_lo_hz = f->band_lo_hz;
    m.band_hi_hz = f->band_hi_hz;
    m.peaks_hz = f->peaks_hz;
    m.signature = describe_feature(catalogue_, *f, w.ref_hz, w.pairs);
    m.share = f->share;
    m.kinematic = f->family != kNoFamily || f->domain == FeatureDomain::kBand ||
                  f->domain == FeatureDomain::kAverage;
    report_.mismatch.push_back(std::move(m));
  }
  // Candidates: the best-ranked hypotheses, the ones the model can switch on first; then,
  // as many again, the best-ranked bearings read in the waveform's spectrum (their own
  // slots: the lines of a slow impact train, ranked with the gears', would take the slots of
  // the effects read as before).
  for (int pass = 0; pass < 2; ++pass) {
    std::size_t taken = 0;
    for (const HypothesisScore& s : w.located.ranking) {
      if (taken >= config_.max_candidates) break;
      const Hypothesis& h = catalogue_.hypotheses[s.hypothesis];
      const bool spectrum_bearing = is_bearing(h.effect) && h.domain == Domain::kSpectrum;
      if (spectrum_bearing != (pass == 1)) continue;
      // One candidate per effect and location.
      bool seen = false;
      for (const CandidateResult& o : report_.candidates)
        if (o.effect == h.effect && o.location == h.location) seen = true;
      if (seen) continue;
      CandidateResult c;
      c.hypothesis = s.hypothesis;
      c.effect = h.effect;
      c.location = h.location;
      c.explanation = h.explanation;
      c.prior_score = s.score;
      c.modelled = !simulator_.parameters(h).empty();
      if (!c.modelled)
        c.verdict = "the dynamics model has no term for it: not modelled, not reported";
      report_.candidates.push_back(std::move(c));
      ++taken;
    }
  }
  w.candidate = 0;
}

bool Diagnoser::step_refit() {
  Work& w = *work_;
  // Skip candidates that cannot be modelled.
  while (w.candidate < report_.candidates.size() && !report_.candidates[w.candidate].modelled &&
         !w.tr)
    ++w.candidate;
  if (w.candidate >= report_.candidates.size()) {
    stage_ = DiagnosisStage::kDecide;
    return true;
  }
  CandidateResult& c = report_.candidates[w.candidate];
  const Hypothesis& h = catalogue_.hypotheses[c.hypothesis];
  AnalysisConfig a = config_.analysis;
  a.band_max_hz = 0.45 * w.sim_fs;
  if (!w.tr && !w.holdout_pending) {
    // Set up the fit: the hypothesis's lines significant on half A.
    w.params = simulator_.parameters(h);
    if (h.effect == Effect::kHousingResonance) {
      // Start a resonance where locate fitted it: its frequency within −15 %/+18 %, its damping.
      const ResidualFeature* band = nullptr;
      for (const ResidualFeature& f : w.located.features)
        if (f.domain == FeatureDomain::kBand && f.channel < w.pairs.size() &&
            w.pairs[f.channel].location == h.location &&
            (band == nullptr || f.fit_share * f.strength > band->fit_share * band->strength))
          band = &f;
      for (EffectParameter& p : w.params) {
        if (band == nullptr) break;
        if (p.name.find("frequency") != std::string::npos) {
          p.lower = std::max(p.lower, band->resonance_hz / 1.18);
          p.upper = std::min(p.upper, band->resonance_hz * 1.18);
          p.initial = std::clamp(band->resonance_hz, p.lower, p.upper);
        } else if (p.name.find("damping") != std::string::npos) {
          p.initial = std::clamp(band->resonance_damping, p.lower, p.upper);
        }
      }
    }
    w.lines.clear();
    const bool env = h.domain == Domain::kEnvelope;
    double rate = 0.0;
    double best_first = 0.0;
    for (std::size_t p = 0; p < kPoints; ++p) {
      const OrderSpectrum& rs = env ? w.rec_a[p].envelope : w.rec_a[p].spectrum;
      const OrderSpectrum& ss = env ? w.sim_cal_half[p].envelope : w.sim_cal_half[p].spectrum;
      if (rs.amplitude.empty()) continue;
      if (h.effect == Effect::kHousingResonance) {
        if (p >= drivetrain_.measurement_points.size() ||
            drivetrain_.measurement_points[p].location != h.location)
          continue;
        for (const ResidualFeature& f : w.located.features) {
          if (f.channel != p || f.domain != FeatureDomain::kBand) continue;
          const double lo = 0.8 * f.band_lo_hz / w.ref_hz, hi = 1.25 * f.band_hi_hz / w.ref_hz;
          for (std::size_t k = 3; k + 3 < ss.amplitude.size(); ++k) {
            const double o = static_cast<double>(k) / static_cast<double>(ss.revolutions);
            if (o < lo || o > hi ||
                !(ss.amplitude[k] >= ss.amplitude[k - 1] && ss.amplitude[k] > ss.amplitude[k + 1]))
              continue;
            const double m = rs.tone(o), n = rs.noise(o);
            if (m >= config_.locate.snr_min * n)
              w.lines.push_back({p, Domain::kSpectrum, o, 0.0, m, n, 1.0});
          }
        }
        continue;
      }
      for (const SignatureLine& l : h.lines) {
        const double top =
            static_cast<double>(rs.amplitude.size() - 3) / static_cast<double>(rs.revolutions);
        if (l.order * (1.0 + h.tolerance) > top) continue;
        const std::vector<double> sync = envelope_exclusions(catalogue_);
        const std::vector<double> gears = spectrum_exclusions(catalogue_);
        const LineMeasure m = measure_line(rs, ss, l.order, h.tolerance, config_.locate,
                                           bearing_exclusions(h, sync, gears));
        if (!m.significant) continue;
        w.lines.push_back(
            {p, h.domain, m.order,
             h.tolerance > 0.0 ? 2.5 / static_cast<double>(rs.revolutions) / m.order : 0.0,
             m.measured, m.noise, l.weight});
        if (l.order == h.lines.front().order && m.measured > best_first) {
          best_first = m.measured;
          rate = m.order;  // the recording's own rate (with slip)
        }
      }
    }
    if (w.lines.empty()) {
      c.verdict = "its lines are not significant on half A: nothing to fit";
      ++w.candidate;
      return true;
    }
    // Keep the strongest lines the trust region can take.
    const std::size_t cap = calibration::kMaxLsqFeatures - kPoints;
    if (w.lines.size() > cap) {
      std::sort(w.lines.begin(), w.lines.end(), [](const FitLine& x, const FitLine& y) {
        return x.measured / x.noise > y.measured / y.noise;
      });
      w.lines.resize(cap);
    }
    // Fit resolution: enough revolutions to separate the hypothesis's lines.
    w.fit_revs = std::max<std::size_t>(
        config_.fit_revolutions,
        h.rate_order > 0.0 ? std::bit_ceil(static_cast<std::size_t>(std::ceil(6.0 / h.rate_order)))
                           : 0);
    w.fit_revs = std::min(w.fit_revs, w.half_a.revs);
    if (is_bearing(h.effect)) {
      // ... and to keep each fit line 3 lines clear of the envelope's synchronous comb, or in
      // the spectrum of the gears' lines (which the simulation carries too: at a coarser
      // resolution their flank reads as the line).
      const std::vector<double> sync = envelope_exclusions(catalogue_);
      const std::vector<double> gears = spectrum_exclusions(catalogue_);
      const std::vector<double>& excl = h.domain == Domain::kEnvelope ? sync : gears;
      auto clear = [&](std::size_t revs) {
        const auto r = static_cast<double>(revs);
        for (const FitLine& l : w.lines)
          for (double o : excl)
            if (std::abs(l.order - o) * r <= 3.0) return false;
        return true;
      };
      while (w.fit_revs < w.half_a.revs && !clear(w.fit_revs))
        w.fit_revs = std::min(2 * w.fit_revs, w.half_a.revs);
    }
    const double measured_rate =
        is_bearing(h.effect) && rate > 0.0 ? rate / h.lines.front().order * h.rate_order : 0.0;
    auto map = std::make_unique<EffectFitMap>(
        simulator_, catalogue_, h, w.params, w.lines, report_.parameters_calibrated, w.op, w.sim_fs,
        w.ref_hz, w.fit_revs, a, w.rec_full.data(), w.env_order, measured_rate, simulations_);
    calibration::TrustRegionConfig tc;
    tc.max_evaluations = config_.fit_evaluations;
    tc.restarts = false;
    // Severities are searched as logarithms and may lie decades from the term's default:
    // long first steps (×e^1.5), up to ×e^3.
    tc.initial_radius = 1.5;
    tc.max_radius = 3.0;
    w.tr = std::make_unique<calibration::TrustRegionLeastSquares>(*map, tc);
    if (!w.tr->config_ok()) {
      c.verdict = "its fit does not fit the least-squares capacity";
      w.tr.reset();
      ++w.candidate;
      return true;
    }
    std::vector<double> target(map->features()), weight(map->features(), 1.0);
    for (std::size_t i = 0; i < w.lines.size(); ++i) {
      target[i] = std::log(w.lines[i].measured);
      weight[i] = w.lines[i].weight;
    }
    for (std::size_t p = 0; p < kPoints; ++p) {
      target[w.lines.size() + p] = std::log(w.rec_a[p].stats.rms);
      weight[w.lines.size() + p] = 2.0;  // f1's threshold, as the calibrator weighs ln RMS
    }
    w.tr->set_target(target.data(), weight.data());
    std::vector<double> x0(w.params.size());
    for (std::size_t i = 0; i < w.params.size(); ++i)
      x0[i] = map->to_search(i, w.params[i].initial);
    w.tr->start(x0.data());
    w.map_impl = std::move(map);
    return true;
  }
  if (w.tr) {
    if (w.tr->step()) return true;
    // Fitted: keep the best point, then judge it on the hold-out half.
    auto* map = static_cast<EffectFitMap*>(w.map_impl.get());
    c.evaluations = w.tr->evaluations();
    c.setting = map->setting(w.tr->best_x().data());
    c.parameters.clear();
    for (std::size_t i = 0; i < w.params.size(); ++i)
      c.parameters.push_back({w.params[i].name, c.setting.values[i]});
    w.tr.reset();
    w.holdout_pending = true;
    return true;
  }
  // Hold-out: the fitted effect over a half window, against both halves.
  w.holdout_pending = false;
  Spectra half{};
  if (!analyse_simulation(simulator_, report_.parameters_calibrated, {c.setting}, w.op, w.sim_fs,
                          w.ref_hz, w.half_a.revs, catalogue_, a, w.env_order, w.rec_full,
                          simulations_, &half, nullptr, 0)) {
    c.verdict = "the model with its term did not simulate: " + simulator_.error();
    ++w.candidate;
    return true;
  }
  const double max_hz = config_.analysis.max_frequency_hz;
  c.residual_fit_calibrated = spectral_residual(w.rec_a, w.sim_cal_half, max_hz);
  c.residual_fit_effect = spectral_residual(w.rec_a, half, max_hz);
  c.residual_holdout_calibrated = spectral_residual(w.rec_b, w.sim_cal_half, max_hz);
  c.residual_holdout_effect = spectral_residual(w.rec_b, half, max_hz);
  // The guard unclipped: where the calibrated model already misses more than the recording
  // holds (a gearbox it does not fit), the clipped residual reads 1 with the term and
  // without, and would let a term through that adds energy where the recording has none.
  c.guard_in_bands = is_bearing(h.effect);
  c.guard_holdout_calibrated = c.guard_in_bands ? band_share(w.rec_b, w.sim_cal_half, max_hz)
                                                : spectral_share(w.rec_b, w.sim_cal_half, max_hz);
  c.guard_holdout_effect =
      c.guard_in_bands ? band_share(w.rec_b, half, max_hz) : spectral_share(w.rec_b, half, max_hz);
  // Its signature: the windows of its lines (the fit lines for a resonance; in the envelope
  // without the synchronous comb, as locate reads it).
  const std::vector<double> sync = envelope_exclusions(catalogue_);
  const std::vector<double> gears = spectrum_exclusions(catalogue_);
  const std::vector<double>* excl = bearing_exclusions(h, sync, gears);
  std::array<std::vector<std::size_t>, kPoints> windows;
  for (std::size_t p = 0; p < kPoints; ++p) {
    const OrderSpectrum& rs =
        h.domain == Domain::kEnvelope ? w.rec_b[p].envelope : w.rec_b[p].spectrum;
    if (rs.amplitude.empty()) continue;
    const double r = static_cast<double>(rs.revolutions);
    auto add = [&](double order, double tol) {
      const auto lo = static_cast<long long>(std::floor(order * (1.0 - tol) * r - 2.5));
      const auto hi = static_cast<long long>(std::ceil(order * (1.0 + tol) * r + 2.5));
      for (long long k = std::max(1LL, lo);
           k <= hi && k < static_cast<long long>(rs.amplitude.size()); ++k)
        if (excl == nullptr || !near_any(static_cast<double>(k) / r, r, *excl))
          windows[p].push_back(static_cast<std::size_t>(k));
    };
    if (h.effect == Effect::kHousingResonance) {
      for (const FitLine& l : w.lines)
        if (l.point == p) add(l.order, 0.0);
    } else {
      const double top = static_cast<double>(rs.amplitude.size() - 3) / r;
      for (const SignatureLine& l : h.lines)
        if (l.order * (1.0 + h.tolerance) <= top) add(l.order, h.tolerance);
    }
    std::sort(windows[p].begin(), windows[p].end());
    windows[p].erase(std::unique(windows[p].begin(), windows[p].end()), windows[p].end());
  }
  c.signature_fit_calibrated =
      signature_residual(w.rec_a, w.sim_cal_half, h.domain, is_bearing(h.effect), windows);
  c.signature_fit_effect =
      signature_residual(w.rec_a, half, h.domain, is_bearing(h.effect), windows);
  c.signature_holdout_calibrated =
      signature_residual(w.rec_b, w.sim_cal_half, h.domain, is_bearing(h.effect), windows);
  c.signature_holdout_effect =
      signature_residual(w.rec_b, half, h.domain, is_bearing(h.effect), windows);
  // Its lines' evidence on the hold-out half (against calibration alone).
  const bool env = h.domain == Domain::kEnvelope;
  c.holdout_evidence = 0.0;
  c.lines = 0;
  for (std::size_t p = 0; p < kPoints; ++p) {
    const OrderSpectrum& rs = env ? w.rec_b[p].envelope : w.rec_b[p].spectrum;
    const OrderSpectrum& ss = env ? w.sim_cal_half[p].envelope : w.sim_cal_half[p].spectrum;
    if (rs.amplitude.empty()) continue;
    if (h.effect == Effect::kHousingResonance) {
      for (const FitLine& l : w.lines) {
        if (l.point != p) continue;
        const LineMeasure m = measure_line(rs, ss, l.order, 0.0, config_.locate);
        if (m.significant) {
          c.holdout_evidence += (m.measured * m.measured) / (m.noise * m.noise);
          ++c.lines;
        }
      }
      continue;
    }
    for (const SignatureLine& l : h.lines) {
      const double top =
          static_cast<double>(rs.amplitude.size() - 3) / static_cast<double>(rs.revolutions);
      if (l.order * (1.0 + h.tolerance) > top) continue;
      const LineMeasure m = measure_line(rs, ss, l.order, h.tolerance, config_.locate, excl);
      if (m.significant) {
        c.holdout_evidence += l.weight * (m.measured * m.measured) / (m.noise * m.noise);
        ++c.lines;
      }
    }
  }
  ++w.candidate;
  return true;
}

void Diagnoser::step_decide() {
  const double gate = 1.0 - config_.min_improvement;
  auto judged = [](const CandidateResult& c) {
    return c.modelled && c.signature_holdout_calibrated > 0.0 && c.signature_holdout_effect > 0.0;
  };
  // Each judged candidate's BIC on half B's own-line residual relative to calibration
  // alone's (header): Δ = n·ln(residual with / without its term) + k·ln(n); < 0 where its
  // term is worth its parameters.
  std::vector<double> delta(report_.candidates.size(), 0.0);
  for (std::size_t i = 0; i < report_.candidates.size(); ++i) {
    const CandidateResult& c = report_.candidates[i];
    if (!judged(c)) continue;
    const double n = static_cast<double>(std::max<std::size_t>(c.lines, 1));
    const double k = static_cast<double>(c.parameters.size());
    delta[i] = n * std::log(c.signature_holdout_effect / c.signature_holdout_calibrated) +
               k * std::log(std::max(n, 2.0));
  }
  std::vector<std::size_t> pass;
  for (std::size_t i = 0; i < report_.candidates.size(); ++i) {
    CandidateResult& c = report_.candidates[i];
    if (!judged(c) || !c.verdict.empty()) continue;
    char text[300];
    const double ratio = c.signature_holdout_effect / c.signature_holdout_calibrated;
    if (ratio > gate) {
      std::snprintf(text, sizeof text,
                    "on the hold-out half it leaves %.0f %% of the calibrated residual in its "
                    "lines (needs ≤ %.0f %%)",
                    100.0 * ratio, 100.0 * gate);
    } else if (c.holdout_evidence < config_.locate.min_evidence) {
      std::snprintf(text, sizeof text,
                    "its lines are not significant on the hold-out half (evidence %.0f < %.0f)",
                    c.holdout_evidence, config_.locate.min_evidence);
    } else if (c.signature_fit_effect >= c.signature_fit_calibrated) {
      std::snprintf(text, sizeof text, "it does not improve the half it was fitted on");
    } else if (c.guard_holdout_effect > 1.02 * c.guard_holdout_calibrated) {
      std::snprintf(text, sizeof text,
                    "it raises the hold-out half's total residual%s (not clipped) from %.3f "
                    "to %.3f",
                    c.guard_in_bands ? " (power in 1/12-octave bands)" : "",
                    c.guard_holdout_calibrated, c.guard_holdout_effect);
    } else {
      std::snprintf(
          text, sizeof text,
          "on the hold-out half it leaves %.0f %% of the calibrated residual in its lines "
          "(%.3f → %.3f), its lines' evidence %.0f, BIC %+.1f against calibration alone "
          "(%zu lines, %zu parameters)",
          100.0 * ratio, c.signature_holdout_calibrated, c.signature_holdout_effect,
          c.holdout_evidence, delta[i], c.lines, c.parameters.size());
      pass.push_back(i);
    }
    c.verdict = text;
  }
  // Posterior weights over calibration alone (Δ = 0) and every judged candidate.
  double best = 0.0;
  for (std::size_t i = 0; i < report_.candidates.size(); ++i)
    if (judged(report_.candidates[i])) best = std::min(best, delta[i]);
  double z = std::exp(-0.5 * (0.0 - best));
  for (std::size_t i = 0; i < report_.candidates.size(); ++i)
    if (judged(report_.candidates[i])) z += std::exp(-0.5 * (delta[i] - best));
  for (std::size_t i = 0; i < report_.candidates.size(); ++i) {
    CandidateResult& c = report_.candidates[i];
    if (judged(c)) c.confidence = std::exp(-0.5 * (delta[i] - best)) / z;
  }
  std::sort(pass.begin(), pass.end(), [&](std::size_t a, std::size_t b) {
    return report_.candidates[a].confidence > report_.candidates[b].confidence;
  });
  // Report the most likely; further ones only with lines mostly their own.
  for (std::size_t i : pass) {
    const Hypothesis& h = catalogue_.hypotheses[report_.candidates[i].hypothesis];
    bool overlaps = false;
    for (std::size_t j : report_.missing) {
      const Hypothesis& g = catalogue_.hypotheses[report_.candidates[j].hypothesis];
      if (h.domain != g.domain || h.lines.empty()) continue;
      std::size_t shared = 0;
      for (const SignatureLine& l : h.lines)
        for (const SignatureLine& m : g.lines)
          if (std::abs(l.order - m.order) < 1e-6 * std::max(1.0, l.order)) {
            ++shared;
            break;
          }
      if (2 * shared > h.lines.size()) overlaps = true;
    }
    if (overlaps) {
      report_.candidates[i].verdict += "; its lines are mostly those of an effect already reported";
      continue;
    }
    report_.candidates[i].accepted = true;
    report_.missing.push_back(i);
  }
}

bool Diagnoser::step_final() {
  Work& w = *work_;
  AnalysisConfig a = config_.analysis;
  a.band_max_hz = 0.45 * w.sim_fs;
  std::vector<EffectSetting> effects;
  for (std::size_t i : report_.missing) effects.push_back(report_.candidates[i].setting);
  Spectra after{};
  const Spectra* shown = &w.sim_cal;
  if (!effects.empty()) {
    if (!analyse_simulation(simulator_, report_.parameters_calibrated, effects, w.op, w.sim_fs,
                            w.ref_hz, w.full.revs, catalogue_, a, w.env_order, w.rec_full,
                            simulations_, &after, nullptr, 0)) {
      fail(DiagnosisStatus::kSimulationFailed, "with the reported effects: " + simulator_.error());
      return false;
    }
    report_.residual_after =
        spectral_residual(w.rec_full, after, config_.analysis.max_frequency_hz);
    w.adapter->set_effects(effects);
    ++simulations_;
    if (!w.calibrator->evaluate(report_.parameters_calibrated, report_.fit_after))
      report_.fit_after = report_.fit_calibrated;
    w.adapter->set_effects({});
    shown = &after;
  }
  // Spectra for the report.
  const double max_hz = config_.analysis.max_frequency_hz;
  for (std::size_t p = 0; p < kPoints; ++p) {
    PointSpectra s;
    s.channel = w.pairs.size() > p ? w.pairs[p].channel : "point" + std::to_string(p + 1);
    s.recorded = trace(w.rec_full[p].spectrum, w.ref_hz, max_hz, config_.plot_points);
    s.before = trace(w.sim_before[p].spectrum, w.ref_hz, max_hz, config_.plot_points);
    s.calibrated = trace(w.sim_cal[p].spectrum, w.ref_hz, max_hz, config_.plot_points);
    s.after = trace((*shown)[p].spectrum, w.ref_hz, max_hz, config_.plot_points);
    const double env_hz = std::max(w.env_order, 1.0) * w.ref_hz;
    s.envelope_recorded = trace(w.rec_full[p].envelope, w.ref_hz, env_hz, config_.plot_points / 2);
    s.envelope_calibrated = trace(w.sim_cal[p].envelope, w.ref_hz, env_hz, config_.plot_points / 2);
    s.envelope_after = trace((*shown)[p].envelope, w.ref_hz, env_hz, config_.plot_points / 2);
    s.band = w.rec_full[p].band;
    s.stats = w.rec_full[p].stats;
    for (const ShaftAverage& sa : w.rec_full[p].averages)
      s.shaft_kurtosis.push_back({sa.shaft, sa.tsa.difference_stats.kurtosis});
    report_.spectra.push_back(std::move(s));
  }
  return true;
}

}  // namespace model::diagnosis
