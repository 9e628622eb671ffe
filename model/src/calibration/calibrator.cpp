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

dsp::FeatureConfig with_mesh_orders(dsp::FeatureConfig config, const Kinematics& k,
                                    const Drivetrain& d) {
  const double ref = reference_hz(k, 60.0);  // any speed: orders are ratios
  config.mesh_count = std::min(k.stage_count(), dsp::kMaxMeshes);
  for (std::size_t s = 0; s < config.mesh_count; ++s)
    config.mesh_orders[s] = ref > 0.0 ? k.mesh_hz(s, 60.0) / ref : 0.0;
  // Every shaft's low harmonics are known lines the tone fit separates from the meshes'.
  config.shaft_count = 0;
  for (const Shaft& shaft : d.shafts) {
    const std::optional<double> f = k.shaft_hz(shaft.id, 60.0);
    if (f && ref > 0.0 && config.shaft_count < dsp::kMaxShafts)
      config.shaft_orders[config.shaft_count++] = *f / ref;
  }
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

DynamicsParameters CalibrationSpace::to_parameters(const double* x,
                                                   const DynamicsParameters& base) const {
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
  return std::any_of(indicators.begin(), indicators.end(),
                     [](const Indicators& i) { return !within_thresholds(i); });
}

// ---- Calibrator ----------------------------------------------------------------

Calibrator::Calibrator(VibrationSimulator& simulator, const Drivetrain& drivetrain,
                       const dsp::FeatureConfig& features, const CalibratorConfig& config)
    : simulator_(simulator),
      kinematics_(drivetrain),
      config_(config),
      features_(with_mesh_orders(features, kinematics_, drivetrain)) {
  problem_.owner = this;
  feature_problem_.owner = this;
  const dsp::FeatureConfig& fc = features_.config();
  feature_count_ =
      std::min(kMeasurementPoints * (1 + fc.mesh_count * fc.harmonics), kMaxLsqFeatures);
}

void Calibrator::set_measurement(const std::array<dsp::PointFeatures, kMeasurementPoints>& measured,
                                 const OperatingPoint& op) {
  measured_ = measured;
  op_ = op;
}

bool Calibrator::simulate_features(const DynamicsParameters& params,
                                   std::array<dsp::PointFeatures, kMeasurementPoints>& out) {
  const double ref_hz = reference_hz(kinematics_, op_.rotor_speed_rpm);
  if (features_.config_status() != dsp::DspStatus::kOk || !(ref_hz > 0.0)) return false;
  std::array<WaveformView, kMeasurementPoints> waves{};
  // Two extra revolutions: the tracker starts one sample in and interpolates cubically.
  const double duration_s = features_.required_duration_s(ref_hz) + 1.0 / ref_hz;
  if (!simulator_.simulate(params, op_, duration_s, waves)) return false;
  for (std::size_t pt = 0; pt < kMeasurementPoints; ++pt) {
    const dsp::DspStatus s =
        features_.extract(waves[pt].samples, waves[pt].count, waves[pt].sample_rate_hz,
                          {nullptr, 0, ref_hz}, out[pt]);
    if (s != dsp::DspStatus::kOk) return false;
  }
  return true;
}

bool Calibrator::evaluate(const DynamicsParameters& params, PointIndicators& out) {
  std::array<dsp::PointFeatures, kMeasurementPoints> simulated{};
  if (!simulate_features(params, simulated)) return false;
  for (std::size_t pt = 0; pt < kMeasurementPoints; ++pt)
    out[pt] = compute_indicators(simulated[pt], measured_[pt]);
  return true;
}

namespace {
// φ of one point (see the header): ln RMS, then ln of every tone's amplitude.
// A floor keeps the logarithm finite for a tone the model does not excite.
constexpr double kLogFloor = 1e-300;
void log_features(const dsp::PointFeatures& f, double* phi) {
  phi[0] = std::log(std::max(f.rms, kLogFloor));
  for (std::size_t i = 0; i < f.count; ++i)
    phi[1 + i] = std::log(std::max(f.amplitude[i], kLogFloor));
}
}  // namespace

bool Calibrator::evaluate_variables(const double* x, double* f, double* phi) {
  ++problem_.evaluations;
  for (std::size_t k = 0; k < kCalibrationObjectives; ++k) f[k] = kIndicatorPenalty;
  const DynamicsParameters p = config_.space.to_parameters(x, base_);
  std::array<dsp::PointFeatures, kMeasurementPoints> simulated{};
  if (!simulate_features(p, simulated)) return false;
  PointIndicators ind{};
  double worst = 0.0;
  for (std::size_t pt = 0; pt < kMeasurementPoints; ++pt) {
    ind[pt] = compute_indicators(simulated[pt], measured_[pt]);
    f[3 * pt + 0] = ind[pt].f1;
    f[3 * pt + 1] = ind[pt].f2;
    f[3 * pt + 2] = ind[pt].f3;
    worst = std::max(
        worst, ind[pt].valid ? worst_threshold_ratio(ind[pt]) : std::numeric_limits<double>::max());
    if (phi) log_features(simulated[pt], phi + pt * (1 + simulated[pt].count));
  }
  problem_.best_ratio = std::min(problem_.best_ratio, worst);
  if (problem_.evaluations_to_threshold == 0 && !needs_calibration(ind)) {
    problem_.evaluations_to_threshold = problem_.evaluations;
  }
  return true;
}

void Calibrator::Problem::evaluate(const double* x, double* f) {
  owner->evaluate_variables(x, f, nullptr);
}

bool Calibrator::FeatureProblem::evaluate(const double* x, double* phi) {
  std::array<double, kCalibrationObjectives> f{};
  const bool ok = owner->evaluate_variables(x, f.data(), phi);
  if (ok) owner->archive_add(x, f.data());
  return ok;
}

void Calibrator::archive_add(const double* x, const double* f) {
  // Pareto archive for minimisation: drop what the new member dominates; skip it
  // when dominated or equal. Full: the new member replaces the one with the
  // largest worst-indicator/threshold when it is better by that measure.
  auto dominates = [](const double* a, const double* b) {
    bool better = false;
    for (std::size_t k = 0; k < kCalibrationObjectives; ++k) {
      if (a[k] > b[k]) return false;
      if (a[k] < b[k]) better = true;
    }
    return better;
  };
  for (std::size_t a = 0; a < archive_n_; ++a) {
    if (dominates(archive_f_[a].data(), f) ||
        std::equal(f, f + kCalibrationObjectives, archive_f_[a].begin())) {
      return;
    }
  }
  std::size_t kept = 0;
  for (std::size_t a = 0; a < archive_n_; ++a) {
    if (!dominates(f, archive_f_[a].data())) {
      archive_f_[kept] = archive_f_[a];
      archive_x_[kept] = archive_x_[a];
      ++kept;
    }
  }
  archive_n_ = kept;
  std::size_t slot = archive_n_;
  if (archive_n_ == kMaxArchive) {
    std::size_t worst = 0;
    for (std::size_t a = 1; a < archive_n_; ++a) {
      if (problem_.preference(archive_f_[a].data()) > problem_.preference(archive_f_[worst].data()))
        worst = a;
    }
    if (problem_.preference(f) >= problem_.preference(archive_f_[worst].data())) return;
    slot = worst;
  } else {
    ++archive_n_;
  }
  std::copy(f, f + kCalibrationObjectives, archive_f_[slot].begin());
  std::copy(x, x + kCalibrationVariables, archive_x_[slot].begin());
}

std::size_t Calibrator::iteration() const {
  if (config_.method == CalibrationMethod::kTrustRegion) return tr_ ? tr_->evaluations() : 0;
  return mogoa_ ? mogoa_->iteration() : 0;
}

std::size_t Calibrator::archive_count() const {
  if (config_.method == CalibrationMethod::kTrustRegion) return archive_n_;
  return mogoa_ ? mogoa_->archive_count() : 0;
}

double Calibrator::archive_objective(std::size_t i, std::size_t k) const {
  if (config_.method == CalibrationMethod::kTrustRegion) return archive_f_[i][k];
  return mogoa_->archive_objective(i, k);
}

bool Calibrator::feature_model(FeatureJacobian& out) const {
  if (!last_model_valid_) return false;
  out = last_model_;
  return true;
}

double Calibrator::Problem::preference(const double* f) const {
  // The worst indicator in units of its threshold: < 1 means everything fits.
  double worst = 0.0;
  for (std::size_t pt = 0; pt < kMeasurementPoints; ++pt) {
    worst = std::max({worst, f[3 * pt] / kF1Threshold, f[3 * pt + 1] / kF2Threshold,
                      f[3 * pt + 2] / kF3Threshold});
  }
  return worst;
}

bool Calibrator::start(const DynamicsParameters& current,
                       const std::optional<DynamicsParameters>& previous,
                       const FeatureJacobian* previous_model) {
  if (features_.config_status() != dsp::DspStatus::kOk) {
    state_ = StepStatus::kFailed;
    return false;
  }
  base_ = current;
  problem_.evaluations = 0;
  problem_.evaluations_to_threshold = 0;
  problem_.best_ratio = 1e300;
  archive_n_ = 0;
  cancel_requested_ = false;
  std::array<double, kCalibrationVariables> x{};
  if (config_.method == CalibrationMethod::kTrustRegion) {
    tr_.emplace(feature_problem_, config_.trust_region);
    if (!tr_->config_ok()) {
      state_ = StepStatus::kFailed;
      return false;
    }
    // Target and weights of the residual (header): the measured log features;
    // ln RMS weighted by 1/f1's threshold, each resolved tone by 1/(f3's threshold·√n).
    std::array<double, kMaxLsqFeatures> target{};
    std::array<double, kMaxLsqFeatures> weight{};
    for (std::size_t pt = 0; pt < kMeasurementPoints; ++pt) {
      const dsp::PointFeatures& m = measured_[pt];
      const std::size_t offset = pt * (1 + m.count);
      if (offset + 1 + m.count > kMaxLsqFeatures) break;
      log_features(m, target.data() + offset);
      weight[offset] = 1.0 / kF1Threshold;
      const std::size_t n = std::max<std::size_t>(m.resolved_count(), 1);
      for (std::size_t i = 0; i < m.count; ++i) {
        weight[offset + 1 + i] =
            m.resolved[i] ? 1.0 / (kF3Threshold * std::sqrt(static_cast<double>(n))) : 0.0;
      }
    }
    tr_->set_target(target.data(), weight.data());
    config_.space.to_variables(previous ? *previous : current, x.data());
    const FeatureJacobian* model = previous_model;
    if (!model && previous && last_model_valid_) model = &last_model_;
    tr_->start(x.data(), model);
    state_ = StepStatus::kRunning;
    return true;
  }
  MogoaConfig mc = config_.mogoa;
  mc.preference_target_share =
      config_.method == CalibrationMethod::kImprovedMogoa ? config_.preference_target_share : 0.0;
  mogoa_.emplace(problem_, mc);
  if (!mogoa_->config_ok()) {
    state_ = StepStatus::kFailed;
    return false;
  }
  if (config_.method == CalibrationMethod::kImprovedMogoa) {
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
  if (cancel_requested_) {
    finish(true);
    return state_;
  }
  const bool more = config_.method == CalibrationMethod::kTrustRegion
                        ? (tr_->step() && !tr_->finished())
                        : mogoa_->step();
  const bool reached = config_.stop_at_threshold && problem_.evaluations_to_threshold != 0;
  if (!more || reached) finish(false);
  return state_;
}

void Calibrator::finish(bool cancelled) {
  // Choose from the archive (see header): fitting members first, nearest the
  // ideal point in threshold units.
  const bool tr = config_.method == CalibrationMethod::kTrustRegion;
  if (tr && tr_->jacobian_valid()) {
    last_model_ = tr_->jacobian();  // the warm start's model for the next calibration
    last_model_valid_ = true;
  }
  const std::size_t n = archive_count();
  std::array<double, kCalibrationObjectives> ideal{};
  ideal.fill(std::numeric_limits<double>::infinity());
  std::array<double, kCalibrationObjectives> f{};
  for (std::size_t a = 0; a < n; ++a) {
    for (std::size_t k = 0; k < kCalibrationObjectives; ++k)
      ideal[k] = std::min(ideal[k], archive_objective(a, k));
  }
  static constexpr std::array<double, 3> kThreshold = {kF1Threshold, kF2Threshold, kF3Threshold};
  std::size_t best = 0;
  bool best_fits = false;
  double best_distance = std::numeric_limits<double>::infinity();
  for (std::size_t a = 0; a < n; ++a) {
    bool fits = true;
    double d2 = 0.0;
    for (std::size_t k = 0; k < kCalibrationObjectives; ++k) {
      f[k] = archive_objective(a, k);
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
  r.iterations = iteration();
  r.evaluations = problem_.evaluations;
  r.evaluations_to_threshold = problem_.evaluations_to_threshold;
  if (n > 0) {
    std::array<double, kCalibrationVariables> x{};
    if (tr) {
      x = archive_x_[best];
    } else {
      mogoa_->archive_member(best, x.data(), nullptr);
    }
    r.parameters = config_.space.to_parameters(x.data(), base_);
    // Re-evaluate the choice: the indicators (and their validity) reported are the chosen
    // parameters' own.
    if (evaluate(r.parameters, r.indicators)) r.fits = !needs_calibration(r.indicators);
  } else {
    r.parameters = base_;
  }
  state_ = cancelled ? StepStatus::kCancelled : StepStatus::kFinished;
  publish(r);
}

void Calibrator::publish(const CalibrationResult& result) {
  result_ = result;
  result_.generation = ++generation_;
}

bool Calibrator::read_result(CalibrationResult& out) const {
  if (generation_ == 0) return false;
  out = result_;
  return true;
}

}  // namespace model::calibration
