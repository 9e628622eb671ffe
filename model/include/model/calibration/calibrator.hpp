#pragma once
// Calibration of the twin (VBDM-DT §2.3.2, §3.2; issue 12): when a similarity indicator
// of either measurement point exceeds its threshold, the uncertain dynamics parameters
// are moved until the simulated vibration matches the recorded one.
//
// Variables: a CalibrationSpace (calibration_space.hpp) — by default the standard space
// of the description's parameters: damping (Rayleigh and band factors), mesh and bearing
// stiffness, each stage's static transmission error, and the housing modes of both
// measurement points — searched in whitened units z (0: the prior, 1: one prior σ).
//
// Features and their weights (trust region): one model evaluation gives, for every
// calibration case (an operating point; several windows of one recording are averaged
// into its measured features), φ = (ln RMS, ln A_1 … ln A_n) of point1, then of point2.
// Each feature carries the uncertainty
//   σ_tone = √(σ_model² + (noise floor / A)²)   for a tone the recording resolves (else
//            the tone is left out), σ_model = tone_model_sd (0.1: what a fit can be
//            expected to reach against a gearbox the model did not simulate);
//   σ_RMS  = rms_model_sd (0.25: the RMS holds broadband content no mesh model has),
// and, when the recording's order spectrum is given (set_measured_spectrum), one more feature
// per point: the square root of the share of the recording's spectral energy the simulation
// does not explain,
//   ρ = √( Σ'_k (a_measured,k − a_simulated,k)² / Σ_k a_measured,k² )   (lines k up to
//       residual_band_hz; Σ' leaves out the lines of the tones the fit compares — their main
//       lobes, ±lobe_half_width lines — which their ln features fit already; the residual
//       of shared/reference/diagnosis-report.md but for those, per point),
// target 0, σ_ρ = residual_model_sd (drivetwin calibrate: 0.25 — ρ² = 1, lines outside the
// tones as strong as the whole recording, costs as much as 16 tones each 10 % off; 0, the
// default: no ρ row, the features as before). The tones and the RMS see
// only the compared lines; ρ also sees every line the model makes that the recording lacks
// (a higher mesh harmonic, a resonance the gearbox does not have) and every line the
// recording has that the model lacks where the model puts something. ρ weighs only in the
// last `residual_rounds` rounds, after the rounds on the tones and RMS have settled (no
// round improving F (below), or max_rounds): they start from the chosen point, the
// candidates judged again by F with ρ, so that the identification (through ρ's column of the
// Jacobian: a tip relief that smooths a stiffness harmonic no tone compares) and the fit
// remove such lines where the indicators allow it — the paper's indicators choose first (a
// point of these rounds on a bound is no success). Weighing ρ from the first round instead
// pulled the structure away from the tones (docs/calibration.md, what was tried).
// The least-squares cost is
//   F(z) = Σ ((φ(z) − φ_measured)/σ)² + w² Σ z²     (Gauss–Newton with the prior, the
//                                                      second sum as one residual per variable;
//                                                      w = prior_weight, 1: the prior as stated)
// Excitation first (every round): the complex tone of mesh harmonic (s, h) at a point is
//   A = P + T · e · exp(iφ)
// — P the tone of the stiffness variation alone (parametric excitation), T the path from that
// harmonic's transmission error to the sensor, e and φ the error's amplitude and phase: the
// model is linear in the error's force k·e. e and φ are what nobody knows for a real gearbox
// (an accuracy grade bounds e within a decade, no more). So each round first solves them for
// the structure at hand (variable projection): one evaluation with every calibrated error at
// zero gives P, one at the current errors gives T, and for every harmonic the recording
// resolves at some point (e, φ) minimise Σ_points w²(ln|P + T e e^{iφ}| − ln A_measured)² plus
// their prior terms — a grid over φ and ln e, no simulation. The solved errors are evaluated;
// `excitation_iterations` re-solve from that evaluation (T again, the stiffness variation's
// cross-terms between harmonics make the map slightly nonlinear); the best point is kept.
// With two points and two unknowns per harmonic the point-to-point ratio still constrains
// the structure: when P is small the ratio is T's, which only the transfer path can change.
// Harmonics no point resolves keep their prior. Then identification and fit as below.
//
// Identifiability (issue 12): from the feature Jacobian J at the start (one forward
// difference per variable, `probe_step` prior σ long), J_w = J/σ in whitened units, the
// variables the recording determines are chosen by orthogonal forward selection (the
// identifiability ranking of Yao et al., Polym. React. Eng. 11 (2003)): repeatedly the
// variable whose column of J_w carries the most information not already carried by the
// chosen ones, ‖residual‖², while that information reduces its posterior σ to at most
// `identify_ratio` of its prior σ (‖residual‖² ≥ 1/ratio² − 1). Two variables that move
// the features alike (a bearing stiffness detuning a resonance, a transmission error
// scaling the tone) thus yield one identified variable, not two unidentified ones. The
// others stay where the round started (the prior, on a cold start) and are reported as
// not identified. The fit: the trust region (trust_region.hpp) over the identified
// variables, its model J taken from the probes (no more probes), the prior's residuals
// included. Resonances make the features strongly nonlinear, so the identification and
// the fit repeat from the best point (up to max_rounds rounds, while a round lowers F by
// more than 1 % and by more than `min_round_gain`, 1: F is a χ², and a change of χ² below 1 is
// not statistically meaningful — Press et al., Numerical Recipes, 3rd ed., §15.5.2 — so the
// rounds stop where they would only fit the noise; "improved" below means both). Warm rounds
// (`warm_rounds`): a round that follows one that lowered F skips the n probes and identifies on the
// model the last round ended with — the probes' columns, those of the variables it fitted replaced
// by the fit's (Broyden-updated along its steps, re-probed by the trust region where its steps
// failed); a warm round that does not improve is followed by a probed one, so the run
// settles only on a freshly probed model. max_rounds (residual_rounds) bounds the probed rounds of
// the stage, and warm rounds go on while the stage's evaluations stay below what that many probed
// rounds may cost, so a run costs at most what it did with every round probed. The spectral
// residual's first round always probes. At the end each variable is reported with its posterior σ
// ratio at the solution (the chosen ones' joint posterior; for the others the information left
// after the chosen) and whether it is identified, not identified, or at a bound (an identified
// variable within 1e-3 σ of its bound).
// The chosen parameters: the evaluated set with every indicator within its threshold and no
// variable on a bound (within 1e-3 σ: the recording asks for more than the physical range)
// with the least F; if none, the least F (then reported NOT calibrated or at its bound).
//
// Joint calibration: set_measurements() takes up to kMaxCalibrationCases operating
// points; one parameter set is fitted to all of them (features concatenated), the
// indicators are reported per case.
//
// Optimisers (CalibrationMethod): kTrustRegion (default, above); kImprovedMogoa and
// kPublishedMogoa search the whole space (no identification) on the six indicators
// (the worst over the cases), choosing from their Pareto archive the member with every
// indicator within its threshold nearest the ideal point (threshold units), else the
// nearest — kept for the comparison with the peers (tools/calibration/calibration_bench).
//
// Warm start: start(current, previous, previous_model): the trust region starts from
// `previous` and, with `previous_model` (feature_model() of the last run: the Jacobian of
// every variable), skips the probes — identification and the first step come from it.
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

#include <Eigen/Cholesky>

#include <array>
#include <complex>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <type_traits>
#include <vector>

#include "model/calibration/calibration_space.hpp"
#include "model/calibration/indicators.hpp"
#include "model/calibration/mogoa.hpp"
#include "model/calibration/simulator.hpp"
#include "model/calibration/trust_region.hpp"
#include "model/drivetrain/description.hpp"
#include "model/drivetrain/kinematics.hpp"
#include "model/dsp/mesh_features.hpp"

namespace model::calibration {

inline constexpr std::size_t kCalibrationObjectives = 3 * kMeasurementPoints;
/// Operating points (calibration cases) a joint calibration fits at once.
inline constexpr std::size_t kMaxCalibrationCases = 4;

using PointIndicators = std::array<Indicators, kMeasurementPoints>;

/// True when any indicator of either point is above its threshold (or invalid):
/// the paper's trigger for a calibration.
bool needs_calibration(const PointIndicators& indicators);

/// One calibration space's outcome, as the choice between nested spaces sees it.
struct SpaceOutcome {
  bool calibrated = false;   // every indicator within its threshold, no fitted variable at a bound
  double worst_ratio = 0.0;  // worst indicator / threshold over every case and point (≤ 1 fits)
};

enum class SpaceChoice : std::uint8_t { kSimpler, kRicher };

/// Nested-model selection (docs/calibration.md): a richer space (the simpler one plus physics,
/// e.g. the gearbox body) is fitted only when the simpler one did not calibrate — richer
/// physics only when the simpler cannot explain the data.
bool should_try_richer(const SpaceOutcome& simpler);

/// Of the two fits, the one that calibrated; both or neither: the lower worst ratio, the
/// simpler on a tie (it is never worse to explain the data with less).
SpaceChoice choose_space(const SpaceOutcome& simpler, const SpaceOutcome& richer);

/// Worst indicator / threshold over the first `cases` cases of `indicators`.
double worst_case_ratio(const std::array<PointIndicators, kMaxCalibrationCases>& indicators,
                        std::size_t cases);

enum class CalibrationMethod : std::uint8_t {
  kPublishedMogoa,  // MOGOA as published, random initial population
  kImprovedMogoa,   // + warm start (current and previous parameters) + preference-guided target
  kTrustRegion,  // identification + Gauss–Newton with the prior (see above); warm start reuses J
};

/// The model of the features the trust region builds: ∂φ/∂z (rows: the data features of
/// every case, columns: every variable of the space), for a warm start.
using FeatureJacobian = TrustRegionLeastSquares::Jacobian;

struct CalibratorConfig {
  CalibrationMethod method = CalibrationMethod::kTrustRegion;
  MogoaConfig mogoa{};  // population, iterations, seed (archive_size kept ≤ kMaxArchive)
  TrustRegionConfig trust_region{};      // budget of the fit (probes come on top), radii, seed
  double preference_target_share = 0.5;  // [-] improved method only
  bool stop_at_threshold = false;        // finish as soon as one evaluated solution fits everywhere
  double tone_model_sd = 0.1;            // [ln] model error allowance per tone (header)
  double rms_model_sd = 0.25;            // [ln] the same for the RMS
  double residual_model_sd = 0.0;    // [-] σ of the spectral residual ρ (header); 0: no ρ row
                                     // (drivetwin calibrate: 0.25)
  double residual_band_hz = 5000.0;  // [Hz] ρ's lines: 1 … this frequency
  std::size_t residual_rounds = 2;   // [-] rounds with ρ after the tones' rounds (header)
  double prior_weight = 1.0;         // [-] weight of the prior's residuals z (header); 0:
                                     // no regularisation (an exact, fully determined map)
  double identify_ratio = 0.5;       // [-] posterior/prior σ at or below: identified
  double probe_step = 0.1;           // [prior σ] identification probe length
  bool identify = true;              // false: fit every variable (no identification)
  std::size_t max_rounds = 8;        // [-] identification + fit rounds (header)
  double min_round_gain = 1.0;       // [χ²] a round improves F only when it lowers F by more
                                     // than this as well as by 1 % (header); 0: by 1 % alone
  bool warm_rounds = true;           // a round after one that improved F reuses its model
                                     // instead of probing again (header); false: every
                                     // round probes every variable
  std::size_t excitation_iterations = 2;  // [-] re-solves of the excitation per round after
                                          // its first solve (header); 0: one solve only
  bool solve_excitation = true;           // false: no excitation solve (header)
  CalibrationSpace space{};               // empty: CalibrationSpace::standard(description's)
};

/// The calibration `drivetwin calibrate` runs by default, shared by every caller that wants
/// the same (the diagnosis's calibration stage among them): the standard space around the
/// description's parameters, with the nominal damping (lumped_simulator.hpp) where the
/// description gives none; a Calibrator given an empty space uses it. `seat_paths`: with the
/// participations of the housing modes at the seats of the parallel-stage bearings that carry
/// no sensor (DynamicsParameters::housing_seat_participation; `calibrate --space seats`).
/// `gearbox_body`: with the gearbox body on its mounts, at the description's values or, where
/// it has none, at the engineering prior (with_nominal_gearbox_body(); `calibrate --space body`).
CalibrationSpace default_space(const Drivetrain& d, bool seat_paths = false,
                               bool gearbox_body = false);
/// Fit evaluations of the trust region per round by default (the probes come on top); what
/// they reach on the independent-generator recordings is Table 3 of docs/calibration.md.
inline constexpr std::size_t kDefaultFitEvaluations = 30;

/// How a calibration left a variable.
enum class VariableStatus : std::uint8_t {
  kNotIdentified,  // the recording cannot determine it: kept where it started
  kIdentified,     // fitted
  kAtLowerBound,   // fitted, ended at its lower bound: not a success
  kAtUpperBound,
};
const char* to_string(VariableStatus s);

/// What a calibration produced; trivially copyable so that the application can publish it
/// through a lock-free mailbox.
struct CalibrationResult {
  std::uint32_t generation = 0;  // [-] 1 for the first published result, +1 per publication
  bool finished = false;         // the optimiser ran to its end (or to the threshold)
  bool cancelled = false;
  bool fits = false;  // every indicator of the chosen parameters within its threshold (all cases)
  bool at_bound = false;            // some fitted variable ended at a bound
  DynamicsParameters parameters{};  // chosen parameters
  PointIndicators indicators{};     // their indicators (the first case)
  std::array<PointIndicators, kMaxCalibrationCases> case_indicators{};  // every case's
  std::size_t cases = 0;
  std::size_t iterations = 0;                // [-] MOGOA iterations / trust-region steps made
  std::size_t evaluations = 0;               // [-] model evaluations made (probes included)
  std::size_t evaluations_to_threshold = 0;  // [-] at the first fitting evaluation; 0: none
  std::size_t variables = 0;                 // [-] of the space
  std::size_t identified = 0;                // [-] variables identified and fitted
  std::size_t rounds = 0;                    // [-] trust-region rounds (both stages)
  std::size_t probed_rounds = 0;             // [-] of them, those that probed (not warm)
  std::array<VariableStatus, kMaxCalibrationVariables> status{};
  std::array<double, kMaxCalibrationVariables> z{};                // [prior σ] chosen, whitened
  std::array<double, kMaxCalibrationVariables> posterior_ratio{};  // [-] posterior/prior σ
  double cost = 0.0;                                               // [-] F of the chosen parameters
};
static_assert(std::is_trivially_copyable_v<CalibrationResult>);

enum class StepStatus : std::uint8_t { kIdle, kRunning, kFinished, kCancelled, kFailed };

/// One operating point's measurement: the measured features of both points.
struct CalibrationCase {
  std::array<dsp::PointFeatures, kMeasurementPoints> measured{};
  OperatingPoint op{};
};

class Calibrator {
 public:
  /// @param simulator  the dynamics model (outlives the calibrator)
  /// @param drivetrain its description (outlives the calibrator); its `dynamics` are the
  ///                   prior of the standard space when config.space is empty
  /// @param features   order-tracking/feature configuration; mesh and shaft orders are
  ///                   filled here from the drivetrain (hss as reference shaft)
  Calibrator(VibrationSimulator& simulator, const Drivetrain& drivetrain,
             const dsp::FeatureConfig& features, const CalibratorConfig& config);

  /// The feature configuration to extract the measured features with.
  const dsp::FeatureConfig& feature_config() const { return features_.config(); }
  /// kOk when the configuration can be used; otherwise why not.
  dsp::DspStatus status() const { return features_.config_status(); }
  const CalibrationSpace& space() const { return config_.space; }

  /// Sets one measurement to calibrate against (measured features of point1, point2).
  void set_measurement(const std::array<dsp::PointFeatures, kMeasurementPoints>& measured,
                       const OperatingPoint& op);
  /// Sets up to kMaxCalibrationCases measurements (operating points) for a joint
  /// calibration; false (nothing changed) for 0 or too many.
  bool set_measurements(const CalibrationCase* cases, std::size_t count);
  /// Gives case c's measured order spectrum at `point` (amplitudes, line k at order
  /// k/revolutions of the feature configuration, as FeatureExtractor::order_spectrum(); e.g.
  /// averaged over the windows the features were averaged over), so that the fit also weighs
  /// the spectral residual ρ (header). Copied (storage allocated at construction); call after
  /// set_measurements(), which clears every case's spectrum. False (nothing changed) without
  /// a ρ row (residual_model_sd 0), for a case or point out of range or an empty spectrum.
  bool set_measured_spectrum(std::size_t c, std::size_t point, const double* amplitude,
                             std::size_t lines);
  /// The spectral residual ρ² (header) of the last simulation of case c at `point` against its
  /// measured spectrum; 0 when none was given.
  double residual_share(std::size_t c, std::size_t point) const {
    return c < kMaxCalibrationCases && point < kMeasurementPoints ? residual_sim_[c][point] : 0.0;
  }
  std::size_t cases() const { return case_count_; }

  /// Indicators of `params` against the first case (one simulation per case).
  /// @return false when the simulation or the feature extraction failed
  bool evaluate(const DynamicsParameters& params, PointIndicators& out);
  /// Indicators of every case; out[c] for c < cases().
  bool evaluate_cases(const DynamicsParameters& params,
                      std::array<PointIndicators, kMaxCalibrationCases>& out);

  /// Begins a calibration from `current` (the fields not in the space are kept).
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
  /// The current Pareto archive: size and objective k (f1, f2, f3 of point1, then of point2;
  /// the worst over the cases) of member i.
  std::size_t archive_count() const;
  double archive_objective(std::size_t i, std::size_t k) const;
  /// The feature Jacobian over every variable after the last trust-region run; false when
  /// none (no trust-region run finished its model yet).
  bool feature_model(FeatureJacobian& out) const;
  /// Number of data features φ (cases × 2 × (1 + mesh tones (+ 1: ρ))) and the trust region's
  /// radius.
  std::size_t feature_count() const { return feature_count_; }
  double trust_radius() const { return tr_ ? tr_->radius() : 0.0; }
  /// Smallest worst_threshold_ratio over both points and every case seen so far (≤ 1: fits).
  double best_ratio() const { return problem_.best_ratio; }
  /// During/after a trust-region run: true while identifying (the probes).
  bool identifying() const { return phase_ == Phase::kIdentify; }
  /// During a cold trust-region run: true while the excitation levels are read (header).
  bool reading_excitation() const { return phase_ == Phase::kExcitation; }

 private:
  enum class Phase : std::uint8_t { kExcitation, kIdentify, kFit };

  // The MOGOA view: z (whitened, every variable) → 6 indicators (worst over the cases).
  struct Problem : MultiObjectiveProblem {
    Calibrator* owner = nullptr;
    std::size_t evaluations = 0;
    std::size_t evaluations_to_threshold = 0;
    double best_ratio = 1e300;
    std::size_t variables() const override { return owner->config_.space.size(); }
    std::size_t objectives() const override { return kCalibrationObjectives; }
    double lower(std::size_t i) const override { return owner->config_.space.lower(i); }
    double upper(std::size_t i) const override { return owner->config_.space.upper(i); }
    void evaluate(const double* x, double* f) override;
    double preference(const double* f) const override;
  };

  // The trust region's view: the identified variables' z → (data features, their z).
  struct FeatureProblem : FeatureMap {
    Calibrator* owner = nullptr;
    std::size_t variables() const override { return owner->fit_count_; }
    std::size_t features() const override { return owner->feature_count_ + owner->fit_count_; }
    double lower(std::size_t i) const override {
      return owner->config_.space.lower(owner->fit_index_[i]);
    }
    double upper(std::size_t i) const override {
      return owner->config_.space.upper(owner->fit_index_[i]);
    }
    bool evaluate(const double* x, double* phi) override;
  };

  // One evaluation of z (every variable): indicators (worst over the cases) into f
  // (penalties on failure), data features into phi when non-null; counts.
  bool evaluate_variables(const double* z, double* f, double* phi);
  bool simulate_features(const DynamicsParameters& params, std::size_t c,
                         std::array<dsp::PointFeatures, kMeasurementPoints>& out);
  double data_cost(const double* phi) const;
  double prior_cost(const double* z) const;  // prior_weight² Σ z² over every variable
  void consider(const double* z, const double* f, double cost);
  // Orthogonal forward selection on j (header); selection into fit_index_/fit_count_ when
  // `select`, posterior ratios for the current fit_index_ selection into `ratio`.
  void identify(const FeatureJacobian& j, bool select,
                std::array<double, kMaxCalibrationVariables>& ratio);
  // `warm`: the round reuses the model the last round's fit ended with (header) when there is one.
  void begin_round(bool warm);
  // One evaluation of the excitation read-out (header); false when it failed.
  bool excitation_step();
  bool begin_fit();
  void finish(bool cancelled);
  void publish(const CalibrationResult& result);

  VibrationSimulator& simulator_;
  Kinematics kinematics_;
  CalibratorConfig config_;
  dsp::FeatureExtractor features_;
  std::array<CalibrationCase, kMaxCalibrationCases> cases_{};
  std::size_t case_count_ = 0;
  DynamicsParameters base_{};
  Problem problem_;
  FeatureProblem feature_problem_;
  std::optional<Mogoa> mogoa_;
  std::optional<TrustRegionLeastSquares> tr_;
  std::size_t feature_count_ = 0;  // data features of every case
  // Data targets and weights (1/σ, 0 for an unresolved tone).
  std::array<double, kMaxLsqFeatures> target_{};
  std::array<double, kMaxLsqFeatures> weight_{};
  // Measured order spectra for ρ (header): case c, point p at spectrum_[(c·points + p)·lines],
  // `spectrum_lines_` lines each (allocated at construction), their lines used and energy.
  std::vector<double> spectrum_;
  std::vector<unsigned char> spectrum_mask_;               // 1: the line counts in ρ's misfit
  std::array<double, kMaxLsqFeatures> residual_weight_{};  // 1/σ_ρ on ρ's rows once given
  bool residual_active_ = false;    // ρ weighs in the cost (the residual's rounds)
  std::size_t residual_round_ = 0;  // 0: before them; then the residual's round (1-based)
  void set_residual_active(bool on);
  std::size_t spectrum_lines_ = 0;
  std::array<std::array<std::size_t, kMeasurementPoints>, kMaxCalibrationCases> residual_lines_{};
  std::array<std::array<double, kMeasurementPoints>, kMaxCalibrationCases> residual_energy_{};
  std::array<std::array<double, kMeasurementPoints>, kMaxCalibrationCases> residual_sim_{};
  std::size_t per_point() const;  // data features per point: 1 + tones (+ 1: ρ)
  bool has_residual_row() const { return config_.residual_model_sd > 0.0; }
  // Trust-region run: identification then fit.
  Phase phase_ = Phase::kIdentify;
  std::size_t probe_ = 0;  // 0: the start point; i + 1: variable i
  // Excitation solve (header): step 0 simulates the errors at zero (P), then each step
  // evaluates the current point (its tones give T) and solves; both read last_features_.
  std::size_t excitation_iteration_ = 0;
  std::array<std::complex<double>, kMaxLsqFeatures> tone_parametric_{};  // P per tone feature
  std::array<std::complex<double>, kMaxLsqFeatures> tone_current_{};     // A at z_start_
  // The amplitude and phase variables of each error harmonic (index into the space; n: none).
  std::array<std::size_t, kTransmissionErrorStages * kTransmissionErrorHarmonics> te_amplitude_{};
  std::array<std::size_t, kTransmissionErrorStages * kTransmissionErrorHarmonics> te_phase_{};
  bool has_excitation_ = false;
  // Variables the run determined: fitted in some round or solved from resolved tones.
  std::array<bool, kMaxCalibrationVariables> determined_{};
  std::array<std::array<dsp::PointFeatures, kMeasurementPoints>, kMaxCalibrationCases>
      last_features_{};                                   // of the last evaluate_variables()
  bool simulate_cases(const DynamicsParameters& params);  // into last_features_
  void solve_excitation();
  std::array<double, kMaxCalibrationVariables> z_start_{};
  std::array<double, kMaxCalibrationVariables> z_work_{};
  std::array<double, kMaxLsqFeatures> phi_start_{};
  std::array<double, kMaxLsqFeatures> phi_work_{};
  std::array<double, kCalibrationObjectives> f_work_{};
  FeatureJacobian model_;      // data features × every variable
  FeatureJacobian fit_model_;  // (data + prior rows) × identified variables
  bool start_model_given_ = false;
  std::array<std::size_t, kMaxCalibrationVariables> fit_index_{};
  std::size_t fit_count_ = 0;
  std::array<double, kMaxCalibrationVariables> ratio_start_{};
  std::size_t round_ = 0;
  bool warm_round_ = false;                  // this round skipped its probes (header: warm rounds)
  std::size_t stage_probed_rounds_ = 0;      // probed rounds of the stage (tones, then ρ)
  std::size_t probed_rounds_ = 0;            // of them probed
  std::size_t stage_start_evaluations_ = 0;  // evaluations before the stage began
  std::size_t round_cost() const;            // a probed round's evaluations at most
  double round_start_cost_ = 0.0;
  FeatureJacobian residual_;  // forward selection's work columns
  using Square = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxCalibrationVariables,
                               kMaxCalibrationVariables>;
  using Column = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxCalibrationVariables, 1>;
  Square posterior_;  // J_wᵀJ_w + I
  Eigen::LLT<Square> posterior_llt_;
  Column unit_;
  // Best evaluated sets: fitting every threshold, and overall (least F).
  std::array<double, kMaxCalibrationVariables> best_fit_z_{}, best_any_z_{};
  double best_fit_cost_ = 0.0, best_any_cost_ = 0.0;
  bool have_fit_ = false, have_any_ = false;
  FeatureJacobian last_model_;
  bool last_model_valid_ = false;
  StepStatus state_ = StepStatus::kIdle;
  bool cancel_requested_ = false;

  CalibrationResult result_{};  // the last published result (generation_ > 0)
  std::uint32_t generation_ = 0;
};

}  // namespace model::calibration
