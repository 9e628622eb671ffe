#include "model/calibration/calibrator.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace model::calibration {

namespace {
// Reference shaft of the order tracking: the high-speed shaft, where the tacho sits.
constexpr const char* kReferenceShaft = "hss";

double reference_hz(const Kinematics& k, double rotor_rpm) {
  const std::optional<double> f = k.shaft_hz(kReferenceShaft, rotor_rpm);
  return f ? *f : 0.0;
}

dsp::FeatureConfig with_mesh_orders(dsp::FeatureConfig config, const Kinematics& k) {
  const double ref = reference_hz(k, 60.0);  // any speed: orders are ratios
  config.mesh_count = std::min(k.stage_count(), dsp::kMaxMeshes);
  for (std::size_t s = 0; s < config.mesh_count; ++s) config.mesh_orders[s] = ref > 0.0 ? k.mesh_hz(s, 60.0) / ref : 0.0;
  return config;
}
}  // namespace

// ---- CalibrationSpace --------------------------------------------------------

double CalibrationSpace::lower(std::size_t i) const {
  if (i == 0) return std::log(eta_min_1_s);
  if (i == 1) return std::log(zeta_min_s);
  return std::log(i < 5 ? mesh_scale_min : bearing_scale_min);
}

double CalibrationSpace::upper(std::size_t i) const {
  if (i == 0) return std::log(eta_max_1_s);
  if (i == 1) return std::log(zeta_max_s);
  return std::log(i < 5 ? mesh_scale_max : bearing_scale_max);
}

DynamicsParameters CalibrationSpace::to_parameters(const double* x, const DynamicsParameters& base) const {
  DynamicsParameters p = base;
  p.rayleigh_eta = std::exp(x[0]);
  p.rayleigh_zeta = std::exp(x[1]);
  for (std::size_t s = 0; s < 3; ++s) {
    p.mesh_stiffness_scale[s] = std::exp(x[2 + s]);
    p.bearing_stiffness_scale[s] = std::exp(x[5 + s]);
  }
  return p;
}

void CalibrationSpace::to_variables(const DynamicsParameters& p, double* x) const {
  auto log_clamped = [&](double v, std::size_t i) {
    return std::clamp(v > 0.0 ? std::log(v) : lower(i), lower(i), upper(i));
  };
  x[0] = log_clamped(p.rayleigh_eta, 0);
  x[1] = log_clamped(p.rayleigh_zeta, 1);
  for (std::size_t s = 0; s < 3; ++s) {
    x[2 + s] = log_clamped(p.mesh_stiffness_scale[s], 2 + s);
    x[5 + s] = log_clamped(p.bearing_stiffness_scale[s], 5 + s);
  }
}

bool needs_calibration(const PointIndicators& indicators) {
  return std::any_of(indicators.begin(), indicators.end(), [](const Indicators& i) { return !within_thresholds(i); });
}

// ---- Calibrator ----------------------------------------------------------------

Calibrator::Calibrator(VibrationSimulator& simulator, const Drivetrain& drivetrain, const dsp::FeatureConfig& features,
                       const CalibratorConfig& config)
    : simulator_(simulator),
      kinematics_(drivetrain),
      config_(config),
      features_(with_mesh_orders(features, kinematics_)) {
  problem_.owner = this;
}

void Calibrator::set_measurement(const std::array<dsp::PointFeatures, kMeasurementPoints>& measured,
                                 const OperatingPoint& op) {
  measured_ = measured;
  op_ = op;
}

bool Calibrator::evaluate(const DynamicsParameters& params, PointIndicators& out) {
  const double ref_hz = reference_hz(kinematics_, op_.rotor_speed_rpm);
  if (features_.config_status() != dsp::DspStatus::kOk || !(ref_hz > 0.0)) return false;
  std::array<WaveformView, kMeasurementPoints> waves{};
  // Two extra revolutions: the tracker starts one sample in and interpolates cubically.
  const double duration_s = features_.required_duration_s(ref_hz) + 1.0 / ref_hz;
  if (!simulator_.simulate(params, op_, duration_s, waves)) return false;
  for (std::size_t pt = 0; pt < kMeasurementPoints; ++pt) {
    dsp::PointFeatures simulated;
    const dsp::DspStatus s =
        features_.extract(waves[pt].samples, waves[pt].count, waves[pt].sample_rate_hz, {nullptr, 0, ref_hz}, simulated);
    if (s != dsp::DspStatus::kOk) return false;
    out[pt] = compute_indicators(simulated, measured_[pt]);
  }
  return true;
}

void Calibrator::Problem::evaluate(const double* x, double* f) {
  ++evaluations;
  PointIndicators ind{};
  const DynamicsParameters p = owner->config_.space.to_parameters(x, owner->base_);
  if (!owner->evaluate(p, ind)) {
    for (std::size_t k = 0; k < kCalibrationObjectives; ++k) f[k] = kIndicatorPenalty;
    return;
  }
  double worst = 0.0;
  for (std::size_t pt = 0; pt < kMeasurementPoints; ++pt) {
    f[3 * pt + 0] = ind[pt].f1;
    f[3 * pt + 1] = ind[pt].f2;
    f[3 * pt + 2] = ind[pt].f3;
    worst = std::max(worst, ind[pt].valid ? worst_threshold_ratio(ind[pt]) : std::numeric_limits<double>::max());
  }
  best_ratio = std::min(best_ratio, worst);
  if (evaluations_to_threshold == 0 && !needs_calibration(ind)) evaluations_to_threshold = evaluations;
}

double Calibrator::Problem::preference(const double* f) const {
  // The worst indicator in units of its threshold: < 1 means everything fits.
  double worst = 0.0;
  for (std::size_t pt = 0; pt < kMeasurementPoints; ++pt) {
    worst = std::max({worst, f[3 * pt] / kF1Threshold, f[3 * pt + 1] / kF2Threshold, f[3 * pt + 2] / kF3Threshold});
  }
  return worst;
}

bool Calibrator::start(const DynamicsParameters& current, const std::optional<DynamicsParameters>& previous) {
  if (features_.config_status() != dsp::DspStatus::kOk) {
    state_ = StepStatus::kFailed;
    return false;
  }
  base_ = current;
  problem_.evaluations = 0;
  problem_.evaluations_to_threshold = 0;
  problem_.best_ratio = 1e300;
  cancel_requested_.store(false, std::memory_order_relaxed);
  MogoaConfig mc = config_.mogoa;
  mc.preference_target_share =
      config_.method == CalibrationMethod::kImprovedMogoa ? config_.preference_target_share : 0.0;
  mogoa_.emplace(problem_, mc);
  if (!mogoa_->config_ok()) {
    state_ = StepStatus::kFailed;
    return false;
  }
  if (config_.method == CalibrationMethod::kImprovedMogoa) {
    std::array<double, kCalibrationVariables> x{};
    config_.space.to_variables(current, x.data());
    mogoa_->seed_position(x.data());
    if (previous) {
      config_.space.to_variables(*previous, x.data());
      mogoa_->seed_position(x.data());
    }
  }
  state_ = StepStatus::kRunning;
  return true;
}

StepStatus Calibrator::step() {
  if (state_ != StepStatus::kRunning) return state_;
  if (cancel_requested_.load(std::memory_order_relaxed)) {
    finish(true);
    return state_;
  }
  const bool more = mogoa_->step();
  const bool reached = config_.stop_at_threshold && problem_.evaluations_to_threshold != 0;
  if (!more || reached) finish(false);
  return state_;
}

void Calibrator::finish(bool cancelled) {
  // Choose from the archive (see header): fitting members first, nearest the
  // ideal point in threshold units.
  const std::size_t n = mogoa_->archive_count();
  std::array<double, kCalibrationObjectives> ideal{};
  ideal.fill(std::numeric_limits<double>::infinity());
  std::array<double, kCalibrationObjectives> f{};
  for (std::size_t a = 0; a < n; ++a) {
    for (std::size_t k = 0; k < kCalibrationObjectives; ++k) ideal[k] = std::min(ideal[k], mogoa_->archive_objective(a, k));
  }
  static constexpr std::array<double, 3> kThreshold = {kF1Threshold, kF2Threshold, kF3Threshold};
  std::size_t best = 0;
  bool best_fits = false;
  double best_distance = std::numeric_limits<double>::infinity();
  for (std::size_t a = 0; a < n; ++a) {
    bool fits = true;
    double d2 = 0.0;
    for (std::size_t k = 0; k < kCalibrationObjectives; ++k) {
      f[k] = mogoa_->archive_objective(a, k);
      fits = fits && f[k] <= kThreshold[k % 3];
      const double d = (f[k] - ideal[k]) / kThreshold[k % 3];
      d2 += d * d;
    }
    if ((fits && !best_fits) || (fits == best_fits && d2 < best_distance)) {
      best = a;
      best_fits = fits;
      best_distance = d2;
    }
  }
  CalibrationResult r;
  r.finished = !cancelled;
  r.cancelled = cancelled;
  r.iterations = mogoa_->iteration();
  r.evaluations = problem_.evaluations;
  r.evaluations_to_threshold = problem_.evaluations_to_threshold;
  if (n > 0) {
    std::array<double, kCalibrationVariables> x{};
    mogoa_->archive_member(best, x.data(), nullptr);
    r.parameters = config_.space.to_parameters(x.data(), base_);
    // Re-evaluate the choice: the indicators (and their validity) reported are the chosen parameters' own.
    if (evaluate(r.parameters, r.indicators)) r.fits = !needs_calibration(r.indicators);
  } else {
    r.parameters = base_;
  }
  state_ = cancelled ? StepStatus::kCancelled : StepStatus::kFinished;
  publish(r);
}

void Calibrator::publish(const CalibrationResult& result) {
  CalibrationResult r = result;
  r.generation = ++generation_;
  std::array<std::uint64_t, kResultWords> words{};
  std::memcpy(words.data(), &r, sizeof(r));
  const std::uint32_t s = sequence_.load(std::memory_order_relaxed);
  sequence_.store(s + 1, std::memory_order_relaxed);  // odd: writing
  std::atomic_thread_fence(std::memory_order_release);
  for (std::size_t i = 0; i < kResultWords; ++i) result_words_[i].store(words[i], std::memory_order_relaxed);
  sequence_.store(s + 2, std::memory_order_release);
}

bool Calibrator::read_result(CalibrationResult& out) const {
  for (int attempt = 0; attempt < 64; ++attempt) {
    const std::uint32_t s1 = sequence_.load(std::memory_order_acquire);
    if (s1 & 1U) continue;
    std::array<std::uint64_t, kResultWords> words{};
    for (std::size_t i = 0; i < kResultWords; ++i) words[i] = result_words_[i].load(std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_acquire);
    if (sequence_.load(std::memory_order_relaxed) != s1) continue;
    if (s1 == 0) return false;
    std::memcpy(static_cast<void*>(&out), words.data(), sizeof(out));
    return true;
  }
  return false;
}

}  // namespace model::calibration
