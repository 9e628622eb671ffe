#include "model/calibration/calibrator.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>

#include "model/calibration/lumped_simulator.hpp"

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

CalibratorConfig with_space(CalibratorConfig c, const Drivetrain& d) {
  if (c.space.size() == 0) c.space = default_space(d);
  return c;
}

// φ of one point (see the header): ln RMS, then ln of every tone's amplitude.
// A floor keeps the logarithm finite for a tone the model does not excite.
constexpr double kLogFloor = 1e-300;
void log_features(const dsp::PointFeatures& f, double* phi) {
  phi[0] = std::log(std::max(f.rms, kLogFloor));
  for (std::size_t i = 0; i < f.count; ++i)
    phi[1 + i] = std::log(std::max(f.amplitude[i], kLogFloor));
}

constexpr double kBoundTolerance = 1e-3;  // [prior σ] a fitted variable this close is at its bound

/// `otherwise`, or the bound a fitted variable ended on. A bound the prior itself sits on (tip
/// relief 0: unmodified involutes) is where the description put the variable, not a limit the
/// fit ran into: ending there is ending at the prior. A lower bound that stands for zero (an
/// error amplitude, CalibrationVariable::lower_is_zero) is inside the physical range.
VariableStatus bound_status(const CalibrationSpace& space, std::size_t i, double z,
                            VariableStatus otherwise) {
  const double lo = space.lower(i), hi = space.upper(i);
  if (z <= lo + kBoundTolerance && lo < -kBoundTolerance && !space.variable(i).lower_is_zero)
    return VariableStatus::kAtLowerBound;
  if (z >= hi - kBoundTolerance && hi > kBoundTolerance) return VariableStatus::kAtUpperBound;
  return otherwise;
}
}  // namespace

const char* to_string(VariableStatus s) {
  switch (s) {
    case VariableStatus::kNotIdentified:
      return "not identified";
    case VariableStatus::kIdentified:
      return "identified";
    case VariableStatus::kAtLowerBound:
      return "AT LOWER BOUND";
    case VariableStatus::kAtUpperBound:
      return "AT UPPER BOUND";
  }
  return "?";
}

CalibrationSpace default_space(const Drivetrain& d, bool seat_paths, bool gearbox_body) {
  // The seats of the parallel-stage bearings that carry no sensor stand in the housing too
  // (housing_seat_participation): their participations join the space.
  std::array<bool, kHousingSeatBearings> unmeasured{};
  for (std::size_t b = 0; b < kHousingSeatBearings; ++b) {
    const std::string id = "b" + std::to_string(b + kHousingSeatFirstBearing + 1);
    unmeasured[b] =
        seat_paths && std::none_of(d.measurement_points.begin(), d.measurement_points.end(),
                                   [&](const MeasurementPoint& mp) { return mp.location == id; });
  }
  const DynamicsParameters prior = with_nominal_damping(d.dynamics);
  return CalibrationSpace::standard(gearbox_body ? with_nominal_gearbox_body(prior) : prior,
                                    unmeasured);
}

bool needs_calibration(const PointIndicators& indicators) {
  return std::any_of(indicators.begin(), indicators.end(),
                     [](const Indicators& i) { return !within_thresholds(i); });
}

bool should_try_richer(const SpaceOutcome& simpler) { return !simpler.calibrated; }

SpaceChoice choose_space(const SpaceOutcome& simpler, const SpaceOutcome& richer) {
  if (simpler.calibrated != richer.calibrated)
    return simpler.calibrated ? SpaceChoice::kSimpler : SpaceChoice::kRicher;
  return richer.worst_ratio < simpler.worst_ratio ? SpaceChoice::kRicher : SpaceChoice::kSimpler;
}

double worst_case_ratio(const std::array<PointIndicators, kMaxCalibrationCases>& indicators,
                        std::size_t cases) {
  double worst = 0.0;
  for (std::size_t c = 0; c < std::min(cases, kMaxCalibrationCases); ++c) {
    for (const Indicators& i : indicators[c]) worst = std::max(worst, worst_threshold_ratio(i));
  }
  return worst;
}

// ---- Calibrator ----------------------------------------------------------------------------

Calibrator::Calibrator(VibrationSimulator& simulator, const Drivetrain& drivetrain,
                       const dsp::FeatureConfig& features, const CalibratorConfig& config)
    : simulator_(simulator),
      kinematics_(drivetrain),
      config_(with_space(config, drivetrain)),
      features_(with_mesh_orders(features, kinematics_, drivetrain)) {
  problem_.owner = this;
  feature_problem_.owner = this;
  // The error harmonics whose amplitude and phase are both calibrated: solved (header).
  te_amplitude_.fill(config_.space.size());
  te_phase_.fill(config_.space.size());
  for (std::size_t i = 0; i < config_.space.size(); ++i) {
    const CalibrationVariable& v = config_.space.variable(i);
    if (v.index >= te_amplitude_.size()) continue;
    if (v.field == ParameterField::kTransmissionError) te_amplitude_[v.index] = i;
    if (v.field == ParameterField::kTransmissionErrorPhase) te_phase_[v.index] = i;
  }
  for (std::size_t k = 0; k < te_amplitude_.size(); ++k) {
    has_excitation_ =
        has_excitation_ || (config_.solve_excitation && te_amplitude_[k] < config_.space.size() &&
                            te_phase_[k] < config_.space.size());
  }
  spectrum_lines_ = features_.config().samples_per_rev * features_.config().revolutions / 2 + 1;
  spectrum_.assign(kMaxCalibrationCases * kMeasurementPoints * spectrum_lines_, 0.0);
  spectrum_mask_.assign(spectrum_.size(), 0);
  const auto n = static_cast<Eigen::Index>(config_.space.size());
  model_.setZero(0, n);
  last_model_.setZero(0, n);
  posterior_.setZero(n, n);
  unit_.setZero(n);
}

void Calibrator::set_measurement(const std::array<dsp::PointFeatures, kMeasurementPoints>& measured,
                                 const OperatingPoint& op) {
  CalibrationCase c;
  c.measured = measured;
  c.op = op;
  set_measurements(&c, 1);
}

bool Calibrator::set_measurements(const CalibrationCase* cases, std::size_t count) {
  if (count == 0 || count > kMaxCalibrationCases) return false;
  const std::size_t per_case = kMeasurementPoints * per_point();
  if (count * per_case + config_.space.size() > kMaxLsqFeatures) return false;
  case_count_ = count;
  for (std::size_t c = 0; c < count; ++c) cases_[c] = cases[c];
  residual_weight_.fill(0.0);
  for (auto& lines : residual_lines_) lines.fill(0);
  for (auto& e : residual_energy_) e.fill(0.0);
  for (auto& r : residual_sim_) r.fill(0.0);
  feature_count_ = count * per_case;
  // Targets and weights (header): ln RMS with 1/σ_RMS; each resolved tone with
  // 1/√(σ_model² + (floor/A)²); unresolved tones 0.
  target_.fill(0.0);
  weight_.fill(0.0);
  std::size_t offset = 0;
  for (std::size_t c = 0; c < count; ++c) {
    for (std::size_t pt = 0; pt < kMeasurementPoints; ++pt) {
      const dsp::PointFeatures& m = cases_[c].measured[pt];
      log_features(m, target_.data() + offset);
      weight_[offset] = 1.0 / config_.rms_model_sd;
      for (std::size_t i = 0; i < m.count; ++i) {
        if (!m.resolved[i]) continue;
        const double noise = m.amplitude[i] > 0.0 ? m.noise_floor[i] / m.amplitude[i] : 1.0;
        weight_[offset + 1 + i] =
            1.0 / std::sqrt(config_.tone_model_sd * config_.tone_model_sd + noise * noise);
      }
      offset += per_point();  // ρ's row: weight 0 until set_measured_spectrum()
    }
  }
  const auto n = static_cast<Eigen::Index>(config_.space.size());
  model_.setZero(static_cast<Eigen::Index>(feature_count_), n);
  last_model_valid_ = false;
  return true;
}

std::size_t Calibrator::per_point() const {
  const dsp::FeatureConfig& fc = features_.config();
  return 1 + fc.mesh_count * fc.harmonics + (has_residual_row() ? 1 : 0);
}

bool Calibrator::set_measured_spectrum(std::size_t c, std::size_t point, const double* amplitude,
                                       std::size_t lines) {
  if (!has_residual_row() || c >= case_count_ || point >= kMeasurementPoints ||
      amplitude == nullptr || lines < 2)
    return false;
  // ρ's lines: 1 … residual_band_hz (line k at k/revolutions reference-shaft orders).
  const double ref_hz = reference_hz(kinematics_, cases_[c].op.rotor_speed_rpm);
  if (!(ref_hz > 0.0)) return false;
  const double band_lines =
      config_.residual_band_hz / ref_hz * static_cast<double>(features_.config().revolutions);
  const std::size_t used =
      std::min({lines, spectrum_lines_, static_cast<std::size_t>(std::max(0.0, band_lines)) + 1});
  const std::size_t at = (c * kMeasurementPoints + point) * spectrum_lines_;
  double* dst = spectrum_.data() + at;
  unsigned char* mask = spectrum_mask_.data() + at;
  double energy = 0.0;
  for (std::size_t k = 1; k < used; ++k) {
    dst[k] = amplitude[k];
    mask[k] = 1;
    energy += amplitude[k] * amplitude[k];
  }
  if (!(energy > 0.0)) return false;
  // The fitted tones' own lines (their main lobes and first side lobes) are left out of ρ's
  // misfit: their tone features fit them already, in ln units.
  const dsp::FeatureConfig& fc = features_.config();
  const auto revs = static_cast<double>(fc.revolutions);
  const auto reach = static_cast<double>(fc.lobe_half_width);
  const std::size_t row0 = (c * kMeasurementPoints + point) * per_point();
  for (std::size_t s = 0; s < fc.mesh_count; ++s) {
    for (std::size_t h = 1; h <= fc.harmonics; ++h) {
      if (!(weight_[row0 + 1 + s * fc.harmonics + (h - 1)] > 0.0)) continue;
      const double nu = fc.mesh_orders[s] * static_cast<double>(h) * revs;
      const auto first = static_cast<std::size_t>(std::max(1.0, std::ceil(nu - reach)));
      const auto last = static_cast<std::size_t>(std::max(0.0, std::floor(nu + reach)));
      for (std::size_t k = first; k <= last && k < used; ++k) mask[k] = 0;
    }
  }
  residual_lines_[c][point] = used;
  residual_energy_[c][point] = energy;
  const std::size_t row = (c * kMeasurementPoints + point + 1) * per_point() - 1;
  residual_weight_[row] = 1.0 / config_.residual_model_sd;
  weight_[row] = residual_active_ ? residual_weight_[row] : 0.0;
  target_[row] = 0.0;
  return true;
}

bool Calibrator::simulate_features(const DynamicsParameters& params, std::size_t c,
                                   std::array<dsp::PointFeatures, kMeasurementPoints>& out) {
  const OperatingPoint& op = cases_[c].op;
  const double ref_hz = reference_hz(kinematics_, op.rotor_speed_rpm);
  if (features_.config_status() != dsp::DspStatus::kOk || !(ref_hz > 0.0)) return false;
  std::array<WaveformView, kMeasurementPoints> waves{};
  // Two extra revolutions: the tracker starts one sample in and interpolates cubically.
  const double duration_s = features_.required_duration_s(ref_hz) + 1.0 / ref_hz;
  if (!simulator_.simulate(params, op, duration_s, waves)) return false;
  for (std::size_t pt = 0; pt < kMeasurementPoints; ++pt) {
    const dsp::DspStatus s =
        features_.extract(waves[pt].samples, waves[pt].count, waves[pt].sample_rate_hz,
                          {nullptr, 0, ref_hz}, out[pt]);
    if (s != dsp::DspStatus::kOk) return false;
    // ρ² against the measured spectrum (header), from the extraction's order spectrum.
    const std::size_t used = residual_lines_[c][pt];
    residual_sim_[c][pt] = 0.0;
    if (used > 0) {
      const double* m = spectrum_.data() + (c * kMeasurementPoints + pt) * spectrum_lines_;
      const double* a = features_.order_spectrum();
      double miss = 0.0;
      const unsigned char* mask =
          spectrum_mask_.data() + (c * kMeasurementPoints + pt) * spectrum_lines_;
      for (std::size_t k = 1; k < used; ++k) {
        if (mask[k]) miss += (m[k] - a[k]) * (m[k] - a[k]);
      }
      residual_sim_[c][pt] = miss / residual_energy_[c][pt];
    }
  }
  return true;
}

bool Calibrator::evaluate_cases(const DynamicsParameters& params,
                                std::array<PointIndicators, kMaxCalibrationCases>& out) {
  for (std::size_t c = 0; c < case_count_; ++c) {
    std::array<dsp::PointFeatures, kMeasurementPoints> simulated{};
    if (!simulate_features(params, c, simulated)) return false;
    for (std::size_t pt = 0; pt < kMeasurementPoints; ++pt)
      out[c][pt] = compute_indicators(simulated[pt], cases_[c].measured[pt]);
  }
  return true;
}

bool Calibrator::evaluate(const DynamicsParameters& params, PointIndicators& out) {
  std::array<PointIndicators, kMaxCalibrationCases> all{};
  if (case_count_ == 0 || !evaluate_cases(params, all)) return false;
  out = all[0];
  return true;
}

bool Calibrator::evaluate_variables(const double* z, double* f, double* phi) {
  ++problem_.evaluations;
  for (std::size_t k = 0; k < kCalibrationObjectives; ++k) f[k] = kIndicatorPenalty;
  const DynamicsParameters p = config_.space.to_parameters(z, base_);
  bool fits_all = true;
  double worst = 0.0;
  std::size_t offset = 0;
  for (std::size_t k = 0; k < kCalibrationObjectives; ++k) f[k] = 0.0;
  for (std::size_t c = 0; c < case_count_; ++c) {
    std::array<dsp::PointFeatures, kMeasurementPoints> simulated{};
    if (!simulate_features(p, c, simulated)) {
      for (std::size_t k = 0; k < kCalibrationObjectives; ++k) f[k] = kIndicatorPenalty;
      return false;
    }
    last_features_[c] = simulated;
    for (std::size_t pt = 0; pt < kMeasurementPoints; ++pt) {
      const Indicators ind = compute_indicators(simulated[pt], cases_[c].measured[pt]);
      f[3 * pt + 0] = std::max(f[3 * pt + 0], ind.f1);
      f[3 * pt + 1] = std::max(f[3 * pt + 1], ind.f2);
      f[3 * pt + 2] = std::max(f[3 * pt + 2], ind.f3);
      fits_all = fits_all && within_thresholds(ind);
      worst = std::max(worst,
                       ind.valid ? worst_threshold_ratio(ind) : std::numeric_limits<double>::max());
      if (phi) {
        log_features(simulated[pt], phi + offset);
        if (has_residual_row()) phi[offset + per_point() - 1] = std::sqrt(residual_sim_[c][pt]);
      }
      offset += per_point();
    }
  }
  problem_.best_ratio = std::min(problem_.best_ratio, worst);
  if (problem_.evaluations_to_threshold == 0 && fits_all) {
    problem_.evaluations_to_threshold = problem_.evaluations;
  }
  return true;
}

double Calibrator::prior_cost(const double* z) const {
  double c = 0.0;
  for (std::size_t i = 0; i < config_.space.size(); ++i) c += z[i] * z[i];
  return config_.prior_weight * config_.prior_weight * c;
}

double Calibrator::data_cost(const double* phi) const {
  double c = 0.0;
  for (std::size_t i = 0; i < feature_count_; ++i) {
    const double r = weight_[i] * (phi[i] - target_[i]);
    c += r * r;
  }
  return c;
}

void Calibrator::consider(const double* z, const double* f, double cost) {
  const std::size_t n = config_.space.size();
  bool fits = true;
  static constexpr std::array<double, 3> kThreshold = {kF1Threshold, kF2Threshold, kF3Threshold};
  for (std::size_t k = 0; k < kCalibrationObjectives; ++k) fits = fits && f[k] <= kThreshold[k % 3];
  // A point on a bound is no success (the recording asks for more than the physical range):
  // it is never chosen over an evaluated fit within the bounds, and the residual's rounds,
  // which start from the chosen fit, start from one that can stand.
  for (std::size_t i = 0; fits && i < n; ++i) {
    fits = bound_status(config_.space, i, z[i], VariableStatus::kIdentified) ==
           VariableStatus::kIdentified;
  }
  if (fits && (!have_fit_ || cost < best_fit_cost_)) {
    have_fit_ = true;
    best_fit_cost_ = cost;
    std::copy(z, z + n, best_fit_z_.begin());
  }
  if (!have_any_ || cost < best_any_cost_) {
    have_any_ = true;
    best_any_cost_ = cost;
    std::copy(z, z + n, best_any_z_.begin());
  }
}

void Calibrator::Problem::evaluate(const double* x, double* f) {
  owner->evaluate_variables(x, f, nullptr);
}

bool Calibrator::FeatureProblem::evaluate(const double* x, double* phi) {
  Calibrator& o = *owner;
  // The fitted variables from x, the others where the run started.
  o.z_work_ = o.z_start_;
  for (std::size_t i = 0; i < o.fit_count_; ++i) o.z_work_[o.fit_index_[i]] = x[i];
  const bool ok = o.evaluate_variables(o.z_work_.data(), o.f_work_.data(), phi);
  if (!ok) return false;
  // The prior's residuals: one per fitted variable, its z (target 0, weight prior_weight).
  for (std::size_t i = 0; i < o.fit_count_; ++i) phi[o.feature_count_ + i] = x[i];
  o.consider(o.z_work_.data(), o.f_work_.data(), o.data_cost(phi) + o.prior_cost(o.z_work_.data()));
  return true;
}

void Calibrator::identify(const FeatureJacobian& j, bool select,
                          std::array<double, kMaxCalibrationVariables>& ratio) {
  const std::size_t n = config_.space.size();
  const auto m = static_cast<Eigen::Index>(feature_count_);
  // J_w = diag(w)·J.
  residual_ = j;
  for (Eigen::Index r = 0; r < m; ++r) residual_.row(r) *= weight_[static_cast<std::size_t>(r)];
  if (select) {
    fit_count_ = 0;
    const double needed = 1.0 / (config_.identify_ratio * config_.identify_ratio) - 1.0;
    std::array<bool, kMaxCalibrationVariables> chosen{};
    for (std::size_t step = 0; step < n; ++step) {
      std::size_t best = n;
      double best_info = -1.0;
      for (std::size_t k = 0; k < n; ++k) {
        if (chosen[k]) continue;
        const double info = residual_.col(static_cast<Eigen::Index>(k)).squaredNorm();
        if (info > best_info) {
          best_info = info;
          best = k;
        }
      }
      if (best == n || (config_.identify && !(best_info >= needed))) break;
      if (!config_.identify && !(best_info > 0.0)) break;
      chosen[best] = true;
      fit_index_[fit_count_++] = best;
      // Remove the chosen direction from the others (Gram–Schmidt on the residual columns).
      const auto b = static_cast<Eigen::Index>(best);
      const double norm2 = residual_.col(b).squaredNorm();
      if (norm2 > 0.0) {
        for (std::size_t k = 0; k < n; ++k) {
          if (chosen[k]) continue;
          const auto c = static_cast<Eigen::Index>(k);
          const double proj = residual_.col(b).dot(residual_.col(c)) / norm2;
          residual_.col(c) -= proj * residual_.col(b);
        }
      }
    }
    std::sort(fit_index_.begin(), fit_index_.begin() + static_cast<long>(fit_count_));
  }
  // Ratios for the selection: the chosen ones' joint posterior (J_Sᵀ J_S + I)⁻¹, the others'
  // information left after the chosen, 1/√(1 + ‖residual‖²).
  residual_ = j;
  for (Eigen::Index r = 0; r < m; ++r) residual_.row(r) *= weight_[static_cast<std::size_t>(r)];
  const auto k = static_cast<Eigen::Index>(fit_count_);
  posterior_.setIdentity(k, k);
  for (Eigen::Index a = 0; a < k; ++a) {
    for (Eigen::Index b = 0; b < k; ++b) {
      posterior_(a, b) +=
          residual_.col(static_cast<Eigen::Index>(fit_index_[static_cast<std::size_t>(a)]))
              .dot(residual_.col(
                  static_cast<Eigen::Index>(fit_index_[static_cast<std::size_t>(b)])));
    }
  }
  posterior_llt_.compute(posterior_);
  std::array<bool, kMaxCalibrationVariables> in{};
  for (Eigen::Index a = 0; a < k; ++a) {
    in[fit_index_[static_cast<std::size_t>(a)]] = true;
    unit_.setZero(k);
    unit_(a) = 1.0;
    posterior_llt_.matrixL().solveInPlace(unit_);
    ratio[fit_index_[static_cast<std::size_t>(a)]] = std::sqrt(unit_.squaredNorm());
  }
  // Project the chosen columns out of the others.
  for (Eigen::Index a = 0; a < k; ++a) {
    const auto b = static_cast<Eigen::Index>(fit_index_[static_cast<std::size_t>(a)]);
    // Orthonormalise the chosen columns in place among themselves first.
    for (Eigen::Index c = 0; c < a; ++c) {
      const auto q = static_cast<Eigen::Index>(fit_index_[static_cast<std::size_t>(c)]);
      residual_.col(b) -= residual_.col(q).dot(residual_.col(b)) * residual_.col(q);
    }
    const double norm = residual_.col(b).norm();
    if (norm > 0.0) residual_.col(b) /= norm;
  }
  for (std::size_t v = 0; v < n; ++v) {
    if (in[v]) continue;
    const auto c = static_cast<Eigen::Index>(v);
    for (Eigen::Index a = 0; a < k; ++a) {
      const auto q = static_cast<Eigen::Index>(fit_index_[static_cast<std::size_t>(a)]);
      residual_.col(c) -= residual_.col(q).dot(residual_.col(c)) * residual_.col(q);
    }
    ratio[v] = 1.0 / std::sqrt(1.0 + residual_.col(c).squaredNorm());
  }
}

bool Calibrator::begin_fit() {
  // Identified variables (header): orthogonal forward selection on the probes' model.
  identify(model_, true, ratio_start_);
  if (fit_count_ == 0) return false;
  for (std::size_t k = 0; k < fit_count_; ++k) determined_[fit_index_[k]] = true;
  // The trust region over them, its model from the probes plus the prior rows.
  const auto m = static_cast<Eigen::Index>(feature_count_ + fit_count_);
  fit_model_.setZero(m, static_cast<Eigen::Index>(fit_count_));
  for (std::size_t k = 0; k < fit_count_; ++k) {
    fit_model_.col(static_cast<Eigen::Index>(k)).head(static_cast<Eigen::Index>(feature_count_)) =
        model_.col(static_cast<Eigen::Index>(fit_index_[k]));
    fit_model_(static_cast<Eigen::Index>(feature_count_ + k), static_cast<Eigen::Index>(k)) = 1.0;
  }
  tr_.emplace(feature_problem_, config_.trust_region);
  if (!tr_->config_ok()) return false;
  std::array<double, kMaxLsqFeatures> target = target_;
  std::array<double, kMaxLsqFeatures> weight = weight_;
  for (std::size_t k = 0; k < fit_count_; ++k) {
    target[feature_count_ + k] = 0.0;
    weight[feature_count_ + k] = config_.prior_weight;
  }
  tr_->set_target(target.data(), weight.data());
  std::array<double, kMaxCalibrationVariables> x{};
  for (std::size_t k = 0; k < fit_count_; ++k) x[k] = z_start_[fit_index_[k]];
  // The round's start point was evaluated already (phi_start_): the fit's first step moves.
  phi_work_ = phi_start_;
  for (std::size_t k = 0; k < fit_count_; ++k) phi_work_[feature_count_ + k] = x[k];
  tr_->start(x.data(), &fit_model_, phi_work_.data());
  phase_ = Phase::kFit;
  return true;
}

std::size_t Calibrator::iteration() const {
  if (config_.method == CalibrationMethod::kTrustRegion) return problem_.evaluations;
  return mogoa_ ? mogoa_->iteration() : 0;
}

std::size_t Calibrator::archive_count() const {
  if (config_.method == CalibrationMethod::kTrustRegion) return 0;
  return mogoa_ ? mogoa_->archive_count() : 0;
}

double Calibrator::archive_objective(std::size_t i, std::size_t k) const {
  return mogoa_ ? mogoa_->archive_objective(i, k) : 0.0;
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
  if (features_.config_status() != dsp::DspStatus::kOk || case_count_ == 0 ||
      config_.space.size() == 0) {
    state_ = StepStatus::kFailed;
    return false;
  }
  base_ = current;
  problem_.evaluations = 0;
  problem_.evaluations_to_threshold = 0;
  problem_.best_ratio = 1e300;
  have_fit_ = have_any_ = false;
  cancel_requested_ = false;
  const std::size_t n = config_.space.size();
  if (config_.method == CalibrationMethod::kTrustRegion) {
    config_.space.to_variables(previous ? *previous : current, z_start_.data());
    const FeatureJacobian* given = previous_model;
    if (!given && previous && last_model_valid_) given = &last_model_;
    start_model_given_ = given && given->rows() == static_cast<Eigen::Index>(feature_count_) &&
                         given->cols() == static_cast<Eigen::Index>(n);
    if (start_model_given_) model_ = *given;
    phase_ = Phase::kIdentify;
    excitation_iteration_ = 0;
    determined_.fill(false);
    // A cold start solves the excitation first; a warm start steps with its previous model.
    if (has_excitation_ && !start_model_given_) phase_ = Phase::kExcitation;
    probe_ = 0;
    round_ = 0;
    warm_round_ = false;
    stage_probed_rounds_ = 1;  // the first round's (its probes or the given model)
    stage_start_evaluations_ = 0;
    probed_rounds_ = start_model_given_ ? 0 : 1;
    set_residual_active(false);
    residual_round_ = 0;
    round_start_cost_ = std::numeric_limits<double>::infinity();
    fit_count_ = 0;
    tr_.reset();
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
    std::array<double, kMaxCalibrationVariables> x{};
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
  bool more = true;
  if (config_.method != CalibrationMethod::kTrustRegion) {
    more = mogoa_->step();
  } else if (phase_ == Phase::kExcitation) {
    if (!excitation_step()) {
      finish(false);
      return state_;
    }
  } else if (phase_ == Phase::kIdentify) {
    const std::size_t n = config_.space.size();
    if (probe_ == 0) {
      // The start point: its features are the base of the probes.
      if (!evaluate_variables(z_start_.data(), f_work_.data(), phi_start_.data())) {
        finish(false);
        return state_;
      }
      const double cost = data_cost(phi_start_.data()) + prior_cost(z_start_.data());
      consider(z_start_.data(), f_work_.data(), cost);
      if (round_ == 0 || residual_round_ == 1) round_start_cost_ = cost;
      probe_ = (start_model_given_ && round_ == 0) || warm_round_ ? n + 1 : 1;
    } else {
      // Probe variable probe_ − 1 by probe_step prior σ (backwards at the upper bound).
      const std::size_t i = probe_ - 1;
      z_work_ = z_start_;
      double h = config_.probe_step;
      if (z_start_[i] + h > config_.space.upper(i)) h = -h;
      z_work_[i] = z_start_[i] + h;
      const auto col = static_cast<Eigen::Index>(i);
      // A probe is a finite difference, not a candidate: were it kept as the best point, the
      // probed variable would end moved by probe_step while reported not identified (seen
      // in the calibrated twin's null test).
      if (evaluate_variables(z_work_.data(), f_work_.data(), phi_work_.data())) {
        for (std::size_t r = 0; r < feature_count_; ++r)
          model_(static_cast<Eigen::Index>(r), col) = (phi_work_[r] - phi_start_[r]) / h;
      } else {
        model_.col(col).setZero();  // a failed model: treat the direction as insensitive
      }
      ++probe_;
    }
    if (probe_ > n && !begin_fit()) more = false;
  } else {
    more = tr_->step() && !tr_->finished();
    // A round ends: another one from the best point while rounds improve F by > 1 % and by
    // more than min_round_gain (χ²); a warm round that did not improve is followed by a probed
    // one (header). Per stage (the tones, then ρ) at most its limit of probed rounds, and warm
    // ones while the stage's evaluations stay below what that many probed rounds may cost.
    const bool improved =
        have_any_ && best_any_cost_ < std::min(0.99 * round_start_cost_,
                                               round_start_cost_ - config_.min_round_gain);
    const bool warm_next = improved && config_.warm_rounds && tr_->jacobian_valid();
    const std::size_t limit = residual_active_ ? config_.residual_rounds : config_.max_rounds;
    const bool allowed = (warm_next || stage_probed_rounds_ < limit) &&
                         problem_.evaluations - stage_start_evaluations_ < limit * round_cost();
    if (!more && (improved || warm_round_) && allowed) {
      begin_round(warm_next);
      if (residual_active_) ++residual_round_;
      more = true;
    } else if (!more && !residual_active_ && have_any_ && config_.residual_rounds > 0 &&
               std::any_of(residual_weight_.begin(), residual_weight_.end(),
                           [](double w) { return w > 0.0; })) {
      // The tones and RMS settled: the spectral residual's rounds (header), from the chosen
      // point, every candidate judged again by the cost with ρ.
      z_start_ = have_fit_ ? best_fit_z_ : best_any_z_;
      set_residual_active(true);
      have_fit_ = have_any_ = false;
      stage_probed_rounds_ = 0;
      stage_start_evaluations_ = problem_.evaluations;
      begin_round(false);
      residual_round_ = 1;
      more = true;
    }
  }
  const bool reached = config_.stop_at_threshold && problem_.evaluations_to_threshold != 0;
  if (!more || reached) finish(false);
  return state_;
}

bool Calibrator::simulate_cases(const DynamicsParameters& params) {
  for (std::size_t c = 0; c < case_count_; ++c) {
    if (!simulate_features(params, c, last_features_[c])) return false;
  }
  return true;
}

bool Calibrator::excitation_step() {
  const std::size_t per_point = this->per_point();
  const std::size_t blocks = case_count_ * kMeasurementPoints;
  // The tones of the last simulation (last_features_) as complex amplitudes, per feature index.
  const auto read_tones = [&](std::array<std::complex<double>, kMaxLsqFeatures>& out) {
    for (std::size_t b = 0; b < blocks; ++b) {
      const dsp::PointFeatures& f = last_features_[b / kMeasurementPoints][b % kMeasurementPoints];
      for (std::size_t i = 0; i < f.count && 1 + i < per_point; ++i)
        out[b * per_point + 1 + i] = std::polar(f.amplitude[i], f.phase[i]);
    }
  };
  if (excitation_iteration_ == 0) {
    // P: every calibrated error at zero.
    DynamicsParameters p = config_.space.to_parameters(z_start_.data(), base_);
    for (std::size_t k = 0; k < te_amplitude_.size(); ++k) {
      if (te_amplitude_[k] < config_.space.size() && te_phase_[k] < config_.space.size())
        p.transmission_error_m[k] = 0.0;
    }
    ++problem_.evaluations;
    ++excitation_iteration_;
    if (!simulate_cases(p)) {
      phase_ = Phase::kIdentify;  // cannot separate the excitation: fit without the solve
      return true;
    }
    read_tones(tone_parametric_);
    return true;
  }
  // The current point: its tones give T; considered like any evaluation.
  const bool ok = evaluate_variables(z_start_.data(), f_work_.data(), phi_work_.data());
  if (!ok) {
    z_start_ = best_any_z_;
    phase_ = Phase::kIdentify;
    return have_any_;  // the round's start itself failed: nothing to go on from
  }
  consider(z_start_.data(), f_work_.data(),
           data_cost(phi_work_.data()) + prior_cost(z_start_.data()));
  if (excitation_iteration_ > config_.excitation_iterations) {
    z_start_ = best_any_z_;  // the best of the solves (or the round's start)
    phase_ = Phase::kIdentify;
    return true;
  }
  ++excitation_iteration_;
  read_tones(tone_current_);
  solve_excitation();
  return true;
}

void Calibrator::solve_excitation() {
  const dsp::FeatureConfig& fc = features_.config();
  const std::size_t n = config_.space.size();
  const std::size_t per_point = this->per_point();
  const std::size_t blocks = case_count_ * kMeasurementPoints;
  const double pw2 = config_.prior_weight * config_.prior_weight;
  constexpr double kTwoPi = 2.0 * 3.14159265358979323846;
  for (std::size_t k = 0; k < te_amplitude_.size(); ++k) {
    const std::size_t a = te_amplitude_[k];
    const std::size_t ph = te_phase_[k];
    if (a >= n || ph >= n) continue;
    const std::size_t stage = k / kTransmissionErrorHarmonics;
    const std::size_t h = k % kTransmissionErrorHarmonics + 1;
    if (stage >= fc.mesh_count || h > fc.harmonics) continue;
    const std::size_t tone = 1 + stage * fc.harmonics + (h - 1);
    const std::complex<double> x0 =
        std::polar(config_.space.value(a, z_start_[a]), config_.space.value(ph, z_start_[ph]));
    if (std::abs(x0) <= 0.0) continue;
    // The resolved tones of this harmonic: P, T, target, weight.
    std::array<std::complex<double>, 2 * kMaxCalibrationCases> pp{}, tt{};
    std::array<double, 2 * kMaxCalibrationCases> target{}, weight{};
    std::size_t count = 0;
    for (std::size_t b = 0; b < blocks; ++b) {
      const std::size_t idx = b * per_point + tone;
      if (!(weight_[idx] > 0.0)) continue;
      pp[count] = tone_parametric_[idx];
      tt[count] = (tone_current_[idx] - tone_parametric_[idx]) / x0;
      target[count] = target_[idx];
      weight[count] = weight_[idx];
      ++count;
    }
    if (count == 0) continue;
    const double za_lo = config_.space.lower(a);
    const double za_hi = config_.space.upper(a);
    const auto cost = [&](double za, double phi) {
      const std::complex<double> x = std::polar(config_.space.value(a, za), phi);
      double c = 0.0;
      for (std::size_t i = 0; i < count; ++i) {
        const double r =
            weight[i] * (std::log(std::max(std::abs(pp[i] + tt[i] * x), 1e-300)) - target[i]);
        c += r * r;
      }
      const double zp = config_.space.whiten(ph, phi);
      return c + pw2 * (za * za + zp * zp);
    };
    // Coarse grid over the phase (one turn) and the amplitude (its bounds), then finer around
    // the best cell.
    constexpr int kPhases = 72;
    constexpr int kAmplitudes = 61;
    double best = std::numeric_limits<double>::infinity();
    double best_za = z_start_[a];
    double best_phi = config_.space.value(ph, z_start_[ph]);
    for (int i = 0; i < kPhases; ++i) {
      const double phi = -0.5 * kTwoPi + kTwoPi * i / kPhases;
      for (int j = 0; j < kAmplitudes; ++j) {
        const double za = za_lo + (za_hi - za_lo) * j / (kAmplitudes - 1);
        const double c = cost(za, phi);
        if (c < best) {
          best = c;
          best_za = za;
          best_phi = phi;
        }
      }
    }
    const double dphi = kTwoPi / kPhases;
    const double dza = (za_hi - za_lo) / (kAmplitudes - 1);
    for (int level = 0; level < 3; ++level) {
      const double cphi = best_phi;
      const double cza = best_za;
      const double sphi = dphi / std::pow(10.0, level);
      const double sza = dza / std::pow(10.0, level);
      for (int i = -10; i <= 10; ++i) {
        const double phi = cphi + sphi * i / 10.0;
        for (int j = -10; j <= 10; ++j) {
          const double za = std::clamp(cza + sza * j / 10.0, za_lo, za_hi);
          const double c = cost(za, phi);
          if (c < best) {
            best = c;
            best_za = za;
            best_phi = phi;
          }
        }
      }
    }
    // Determined only when the tones depend on the error as the identification demands of any
    // variable (information Σ (w σ ∂ln|A|/∂ln e)² ≥ 1/ratio² − 1 at the solution); else kept.
    const std::complex<double> xb = std::polar(config_.space.value(a, best_za), best_phi);
    double info = 0.0;
    for (std::size_t i = 0; i < count; ++i) {
      const double share = std::abs(tt[i] * xb) / std::max(std::abs(pp[i] + tt[i] * xb), 1e-300);
      const double g = weight[i] * config_.space.variable(a).prior_sd * std::min(share, 1.0);
      info += g * g;
    }
    const double needed = 1.0 / (config_.identify_ratio * config_.identify_ratio) - 1.0;
    if (!(info >= needed)) continue;
    determined_[a] = true;
    determined_[ph] = true;
    // The phase back into (−π, π].
    best_phi = std::remainder(best_phi, kTwoPi);
    z_start_[a] = best_za;
    z_start_[ph] = std::clamp(config_.space.whiten(ph, best_phi), config_.space.lower(ph),
                              config_.space.upper(ph));
  }
}

void Calibrator::set_residual_active(bool on) {
  residual_active_ = on && has_residual_row();
  if (!has_residual_row()) return;
  const std::size_t pp = per_point();
  for (std::size_t b = 0; b < case_count_ * kMeasurementPoints; ++b) {
    const std::size_t row = (b + 1) * pp - 1;
    weight_[row] = residual_active_ ? residual_weight_[row] : 0.0;
  }
}

std::size_t Calibrator::round_cost() const {
  // A probed round's evaluations at most: the excitation solve's, the start, the probes, the fit.
  const std::size_t excitation = has_excitation_ ? config_.excitation_iterations + 2 : 0;
  return excitation + 1 + config_.space.size() + config_.trust_region.max_evaluations;
}

void Calibrator::begin_round(bool warm) {
  // The next round re-identifies at the best point so far (on the switch to the residual's
  // rounds: at the point the caller set, the candidates being reset); a warm one on the
  // model the fit ended with (header), kept in model_ for the probes it skips.
  warm_round_ = false;
  if (config_.warm_rounds && warm && phase_ == Phase::kFit && tr_ && tr_->jacobian_valid()) {
    for (std::size_t k = 0; k < fit_count_; ++k) {
      model_.col(static_cast<Eigen::Index>(fit_index_[k])) =
          tr_->jacobian()
              .col(static_cast<Eigen::Index>(k))
              .head(static_cast<Eigen::Index>(feature_count_));
    }
    warm_round_ = true;
  }
  if (!warm_round_) {
    ++stage_probed_rounds_;
    ++probed_rounds_;
  }
  if (have_any_) {
    z_start_ = best_any_z_;
    round_start_cost_ = best_any_cost_;
  }
  ++round_;
  phase_ = has_excitation_ ? Phase::kExcitation : Phase::kIdentify;
  excitation_iteration_ = 0;
  probe_ = 0;
  tr_.reset();
}

void Calibrator::finish(bool cancelled) {
  const std::size_t n = config_.space.size();
  CalibrationResult r;
  r.finished = !cancelled;
  r.cancelled = cancelled;
  r.iterations = iteration();
  r.variables = n;
  r.cases = case_count_;
  r.rounds = config_.method == CalibrationMethod::kTrustRegion ? round_ + 1 : 0;
  r.probed_rounds = config_.method == CalibrationMethod::kTrustRegion ? probed_rounds_ : 0;
  std::array<double, kMaxCalibrationVariables> z{};
  bool chosen = false;
  if (config_.method == CalibrationMethod::kTrustRegion) {
    // The model over every variable at the end: the fit's (Broyden-updated) columns for the
    // fitted variables, the probes' for the others.
    if (phase_ == Phase::kFit && tr_ && tr_->jacobian_valid()) {
      for (std::size_t k = 0; k < fit_count_; ++k) {
        model_.col(static_cast<Eigen::Index>(fit_index_[k])) =
            tr_->jacobian()
                .col(static_cast<Eigen::Index>(k))
                .head(static_cast<Eigen::Index>(feature_count_));
      }
    }
    const bool model_complete = phase_ == Phase::kFit || start_model_given_;
    if (model_complete) {
      last_model_ = model_;
      last_model_valid_ = true;
    }
    if (have_fit_ || have_any_) {
      z = have_fit_ ? best_fit_z_ : best_any_z_;
      r.cost = have_fit_ ? best_fit_cost_ : best_any_cost_;
      chosen = true;
    }
    std::array<double, kMaxCalibrationVariables> ratio{};
    if (model_complete) {
      identify(model_, false, ratio);
    } else {
      ratio.fill(1.0);
    }
    r.identified = 0;
    for (std::size_t i = 0; i < n; ++i) {
      r.posterior_ratio[i] = ratio[i];
      // Identified: fitted in some round, or solved from resolved tones (the excitation).
      const bool fitted = determined_[i];
      VariableStatus st = fitted ? VariableStatus::kIdentified : VariableStatus::kNotIdentified;
      if (fitted && chosen) st = bound_status(config_.space, i, z[i], st);
      r.status[i] = st;
      r.identified += fitted ? 1 : 0;
      r.at_bound =
          r.at_bound || st == VariableStatus::kAtLowerBound || st == VariableStatus::kAtUpperBound;
    }
  } else if (mogoa_ && mogoa_->archive_count() > 0) {
    // Pareto archive: fitting members first, nearest the ideal point in threshold units.
    const std::size_t count = mogoa_->archive_count();
    std::array<double, kCalibrationObjectives> ideal{};
    ideal.fill(std::numeric_limits<double>::infinity());
    for (std::size_t a = 0; a < count; ++a) {
      for (std::size_t k = 0; k < kCalibrationObjectives; ++k)
        ideal[k] = std::min(ideal[k], mogoa_->archive_objective(a, k));
    }
    static constexpr std::array<double, 3> kThreshold = {kF1Threshold, kF2Threshold, kF3Threshold};
    std::size_t best = 0;
    bool best_fits = false;
    double best_distance = std::numeric_limits<double>::infinity();
    for (std::size_t a = 0; a < count; ++a) {
      bool fits = true;
      double d2 = 0.0;
      for (std::size_t k = 0; k < kCalibrationObjectives; ++k) {
        const double f = mogoa_->archive_objective(a, k);
        fits = fits && f <= kThreshold[k % 3];
        const double d = (f - ideal[k]) / kThreshold[k % 3];
        d2 += d * d;
      }
      if ((fits && !best_fits) || (fits == best_fits && d2 < best_distance)) {
        best = a;
        best_fits = fits;
        best_distance = d2;
      }
    }
    mogoa_->archive_member(best, z.data(), nullptr);
    chosen = true;
    for (std::size_t i = 0; i < n; ++i) {
      // searched (no identification)
      r.status[i] = bound_status(config_.space, i, z[i], VariableStatus::kIdentified);
      r.posterior_ratio[i] = 1.0;
      r.at_bound = r.at_bound || r.status[i] != VariableStatus::kIdentified;
    }
    r.identified = n;
  }
  r.evaluations = problem_.evaluations;
  r.evaluations_to_threshold = problem_.evaluations_to_threshold;
  if (chosen) {
    r.z = z;
    r.parameters = config_.space.to_parameters(z.data(), base_);
    // Re-evaluate the choice: the indicators (and their validity) reported are the chosen
    // parameters' own.
    if (evaluate_cases(r.parameters, r.case_indicators)) {
      r.fits = true;
      for (std::size_t c = 0; c < case_count_; ++c)
        r.fits = r.fits && !needs_calibration(r.case_indicators[c]);
      r.indicators = r.case_indicators[0];
    }
  } else {
    r.parameters = base_;
    config_.space.to_variables(base_, r.z.data());
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
