#pragma once
// Calibration of the twin (VBDM-DT §2.3.2, §3.2): when a similarity
// indicator of either measurement point exceeds its threshold, an optimiser
// moves the uncertain dynamics parameters to minimise the six indicators
// (f1, f2, f3 at point1 and point2) of the simulated against the measured
// vibration, and the calibrator picks, from the Pareto archive of the
// parameter sets it evaluated:
//   the member with every indicator within its threshold that is nearest the
//   ideal point (the archive's component-wise minimum), distances measured in
//   units of each indicator's threshold; if no member is within all
//   thresholds, the member nearest the ideal point.
//
// Decision variables (8): Rayleigh η [1/s] and ζ [s], the mesh stiffness
// scale of each of the 3 stages and the bearing stiffness scale of each of the
// 3 parallel shafts (model::DynamicsParameters). The optimisers search their
// logarithms within CalibrationSpace's bounds (ratios, not differences, are
// what is uncertain about a damping or a stiffness).
//
// Optimisers (CalibrationMethod):
//  - kTrustRegion (default): derivative-free least squares (trust_region.hpp,
//    after DFO-GN, Cartis & Roberts 2019) on the features the indicators are
//    made of. One model evaluation returns the whole feature vector
//      φ = (ln RMS, ln A_1 … ln A_n) of point1, then of point2
//    and the residual is r = w ∘ (φ(x) − φ_measured) with
//      w = 1/0.5 for ln RMS                   (f1's threshold: f1 ≈ |ln RMS ratio|)
//      w = 1/(0.2·√n_p) for each tone that the measurement resolves, 0 for the others
//                                             (f3's threshold: Σ r² = mean (ln ratio)² / 0.2²)
//    so F = ‖r‖² ≈ Σ_points (f1/0.5)² + (f3-like/0.2)²; f2 (shape) follows
//    when the amplitudes match. Cold start: n = 8 probes build J (9
//    evaluations), then one evaluation per iteration. Warm start: the previous
//    calibration's parameters AND its feature Jacobian J (Broyden-updated as
//    the run goes): the first evaluation is already a step of the model.
//  - kImprovedMogoa: MOGOA + the current/previous parameters in the initial
//    population + a preference-guided target (mogoa.hpp).
//  - kPublishedMogoa: MOGOA as published (random initial population).
//
// Thread context: one thread owns the Calibrator (in the box: the low-priority
// calibration thread) and calls start() and then step() until it returns a final
// status; each step() is one model evaluation (trust region) or one MOGOA
// iteration (population × one simulation). Every member, cancel() and
// read_result() included, is called from that thread only: the Calibrator has no
// thread protocol of its own. The application relays a cancel request from
// another thread and publishes results to other threads through its mailboxes
// (app/loop/mailbox.hpp). Construct at start-up: all
// buffers, the FFT plan, the MOGOA and trust-region storage and the archive
// are allocated there; start()/step() do not allocate (the simulator must not
// either for that to hold: the lumped stand-in does not, the dynamics ROM
// adapter does, see dynamics_simulator.hpp).

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <type_traits>

#include "model/calibration/indicators.hpp"
#include "model/calibration/mogoa.hpp"
#include "model/calibration/simulator.hpp"
#include "model/calibration/trust_region.hpp"
#include "model/drivetrain/description.hpp"
#include "model/drivetrain/kinematics.hpp"
#include "model/dsp/mesh_features.hpp"

namespace model::calibration {

inline constexpr std::size_t kCalibrationVariables = 8;
inline constexpr std::size_t kCalibrationObjectives = 3 * kMeasurementPoints;

/// Bounds of the decision variables.
struct CalibrationSpace {
  double eta_min_1_s = 0.5, eta_max_1_s = 50.0;             // [1/s] Rayleigh η
  double zeta_min_s = 1e-6, zeta_max_s = 1e-4;              // [s] Rayleigh ζ
  double mesh_scale_min = 0.5, mesh_scale_max = 2.0;        // [-]
  double bearing_scale_min = 0.5, bearing_scale_max = 2.0;  // [-]

  /// Bounds of variable i in the optimiser's (logarithmic) coordinates.
  double lower(std::size_t i) const;
  double upper(std::size_t i) const;
  /// Variables → parameters (fields not calibrated are copied from `base`).
  DynamicsParameters to_parameters(const double* x, const DynamicsParameters& base) const;
  /// Parameters → variables (clamped into the bounds).
  void to_variables(const DynamicsParameters& p, double* x) const;
};

using PointIndicators = std::array<Indicators, kMeasurementPoints>;

/// True when any indicator of either point is above its threshold (or invalid):
/// the paper's trigger for a calibration.
bool needs_calibration(const PointIndicators& indicators);

enum class CalibrationMethod : std::uint8_t {
  kPublishedMogoa,  // MOGOA as published, random initial population
  kImprovedMogoa,   // + warm start (current and previous parameters) + preference-guided target
  kTrustRegion,  // derivative-free least squares on the features (see above); warm start reuses J
};

/// The trust-region method's model of the features: ∂φ/∂x at the last
/// calibration (rows: features of FeatureLayout, columns: the 8 variables).
using FeatureJacobian = TrustRegionLeastSquares::Jacobian;

struct CalibratorConfig {
  CalibrationMethod method = CalibrationMethod::kTrustRegion;
  MogoaConfig mogoa{};  // population, iterations, seed (archive_size kept ≤ kMaxArchive)
  TrustRegionConfig trust_region{};      // budget, radii, probe basis seed
  double preference_target_share = 0.5;  // [-] improved method only
  bool stop_at_threshold = false;        // finish as soon as one evaluated solution fits everywhere
  CalibrationSpace space{};
};

/// What a calibration produced; trivially copyable so that the application can publish it
/// through a lock-free mailbox.
struct CalibrationResult {
  std::uint32_t generation = 0;  // [-] 1 for the first published result, +1 per publication
  bool finished = false;         // the optimiser ran to its end (or to the threshold)
  bool cancelled = false;
  bool fits = false;                // every indicator of the chosen parameters within its threshold
  DynamicsParameters parameters{};  // chosen parameters
  PointIndicators indicators{};     // their indicators
  std::size_t iterations = 0;       // [-] MOGOA iterations / trust-region steps made
  std::size_t evaluations = 0;      // [-] model evaluations made
  std::size_t evaluations_to_threshold = 0;  // [-] at the first fitting evaluation; 0: none
};
static_assert(std::is_trivially_copyable_v<CalibrationResult>);

enum class StepStatus : std::uint8_t { kIdle, kRunning, kFinished, kCancelled, kFailed };

class Calibrator {
 public:
  /// @param simulator  the dynamics model (outlives the calibrator)
  /// @param drivetrain its description (outlives the calibrator)
  /// @param features   order-tracking/feature configuration; mesh orders are
  ///                   filled here from the drivetrain (hss as reference shaft)
  Calibrator(VibrationSimulator& simulator, const Drivetrain& drivetrain,
             const dsp::FeatureConfig& features, const CalibratorConfig& config);

  /// The feature configuration to extract the measured features with.
  const dsp::FeatureConfig& feature_config() const { return features_.config(); }
  /// kOk when the configuration can be used; otherwise why not.
  dsp::DspStatus status() const { return features_.config_status(); }

  /// Sets the measurement to calibrate against (measured features of point1, point2).
  void set_measurement(const std::array<dsp::PointFeatures, kMeasurementPoints>& measured,
                       const OperatingPoint& op);

  /// Indicators of `params` against the measurement (one simulation).
  /// @return false when the simulation or the feature extraction failed
  bool evaluate(const DynamicsParameters& params, PointIndicators& out);

  /// Begins a calibration from `current` (the fields not calibrated are kept).
  /// `previous`, when given, is the last calibration's result (warm start:
  /// the improved MOGOA seeds it into its population; the trust region starts
  /// from it instead of `current`). `previous_model` is that calibration's
  /// feature Jacobian (feature_model()); when absent, the trust region reuses
  /// this calibrator's own last model if it has one and `previous` is given.
  /// Returns false for an unusable configuration.
  bool start(const DynamicsParameters& current,
             const std::optional<DynamicsParameters>& previous = std::nullopt,
             const FeatureJacobian* previous_model = nullptr);

  /// One model evaluation (trust region) or one MOGOA iteration (the first
  /// step evaluates the initial population). Publishes the result when the run ends.
  StepStatus step();

  /// Requests the running calibration to stop at the next step() (owning thread).
  void cancel() { cancel_requested_ = true; }

  /// Copies the last published result (the end of the last run); false when no run
  /// has ended yet. Owning thread; the result is trivially copyable for a mailbox.
  bool read_result(CalibrationResult& out) const;

  std::size_t evaluations() const { return problem_.evaluations; }
  std::size_t evaluations_to_threshold() const { return problem_.evaluations_to_threshold; }
  std::size_t iteration() const;
  /// The current Pareto archive: size and objective k (f1, f2, f3 of point1, then of point2) of
  /// member i.
  std::size_t archive_count() const;
  double archive_objective(std::size_t i, std::size_t k) const;
  /// The trust region's feature Jacobian after the last run; false when none
  /// (no trust-region run finished its model yet).
  bool feature_model(FeatureJacobian& out) const;
  /// Number of features φ (2 × (1 + mesh tones)) and the trust region's radius.
  std::size_t feature_count() const { return feature_count_; }
  double trust_radius() const { return tr_ ? tr_->radius() : 0.0; }
  /// Smallest worst_threshold_ratio over both points seen so far (≤ 1: fits).
  double best_ratio() const { return problem_.best_ratio; }

 private:
  // The optimiser's view: x (log variables) → 6 indicators.
  struct Problem : MultiObjectiveProblem {
    Calibrator* owner = nullptr;
    std::size_t evaluations = 0;
    std::size_t evaluations_to_threshold = 0;
    double best_ratio = 1e300;
    std::size_t variables() const override { return kCalibrationVariables; }
    std::size_t objectives() const override { return kCalibrationObjectives; }
    double lower(std::size_t i) const override { return owner->config_.space.lower(i); }
    double upper(std::size_t i) const override { return owner->config_.space.upper(i); }
    void evaluate(const double* x, double* f) override;
    double preference(const double* f) const override;
  };

  // The trust region's view: x (log variables) → φ (log features).
  struct FeatureProblem : FeatureMap {
    Calibrator* owner = nullptr;
    std::size_t variables() const override { return kCalibrationVariables; }
    std::size_t features() const override { return owner->feature_count_; }
    double lower(std::size_t i) const override { return owner->config_.space.lower(i); }
    double upper(std::size_t i) const override { return owner->config_.space.upper(i); }
    bool evaluate(const double* x, double* phi) override;
  };

  // One evaluation of x for either optimiser: indicators into f (penalties on
  // failure), log features into phi when non-null; counts and archives (trust region).
  bool evaluate_variables(const double* x, double* f, double* phi);
  bool simulate_features(const DynamicsParameters& params,
                         std::array<dsp::PointFeatures, kMeasurementPoints>& out);
  void archive_add(const double* x, const double* f);
  void finish(bool cancelled);
  void publish(const CalibrationResult& result);

  VibrationSimulator& simulator_;
  Kinematics kinematics_;
  CalibratorConfig config_;
  dsp::FeatureExtractor features_;
  std::array<dsp::PointFeatures, kMeasurementPoints> measured_{};
  OperatingPoint op_{};
  DynamicsParameters base_{};
  Problem problem_;
  FeatureProblem feature_problem_;
  std::optional<Mogoa> mogoa_;
  std::optional<TrustRegionLeastSquares> tr_;
  std::size_t feature_count_ = 0;
  FeatureJacobian last_model_ = FeatureJacobian::Zero();
  bool last_model_valid_ = false;
  // Pareto archive of the trust region's evaluations (MOGOA keeps its own).
  std::size_t archive_n_ = 0;
  std::array<std::array<double, kCalibrationVariables>, kMaxArchive> archive_x_{};
  std::array<std::array<double, kCalibrationObjectives>, kMaxArchive> archive_f_{};
  StepStatus state_ = StepStatus::kIdle;
  bool cancel_requested_ = false;

  CalibrationResult result_{};  // the last published result (generation_ > 0)
  std::uint32_t generation_ = 0;
};

}  // namespace model::calibration
