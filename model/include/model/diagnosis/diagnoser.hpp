#pragma once
// The diagnosis (issue 14) as step-wise, cancellable work, in the shape of
// model::calibration::Calibrator: one thread (in the box: the low-priority calibration
// thread) owns the Diagnoser and calls start() and then step() until it returns a final
// status. Every member, cancel() and read_result() included, is called from that thread
// only: like the Calibrator, the Diagnoser has no thread protocol of its own. Its
// summary (DiagnosisSummary) is trivially copyable so that the application publishes it
// atomically to other threads through its mailboxes (app/loop/mailbox.hpp, Latest<T>),
// after every step if it likes (read_result() is valid from the first step on), and
// relays a cancel request from another thread.
//
// What the steps do, in order (each step is one bounded piece: one analysis, one
// calibrator step or one simulation):
//  1. speed   — the reference shaft's angle: from the tacho pulses when given, else
//               tracked from a mesh line (speed_tracking.hpp), else the operating
//               point's constant speed; the recording is cut into whole revolutions:
//               the full window and its two halves A (fit) and B (hold-out);
//  2. analyse — every measured channel over the full window and both halves
//               (analysis.hpp); the calibrator's features (model/dsp/mesh_features.hpp);
//  3. calibrate — the calibrator (trust region by default) from the description's
//               parameters: fit_before, fit_calibrated;
//  4. simulate — the nominal and the calibrated ROM over the full window at a constant
//               speed: residual_before, residual_calibrated, and what is left;
//  5. locate  — residual features and the ranking of every hypothesis (locate.hpp);
//  6. refit   — for each of the best-ranked hypotheses the dynamics model can switch on
//               (effect_model.hpp): its parameters fitted on half A (trust region on the
//               log amplitudes of its lines and the RMS of each point, the calibration
//               parameters held at their calibrated values, then optionally the
//               calibrator run again with the effect switched on), then simulated and
//               compared on half B, which the fit never saw;
//  7. decide  — judged on its signature: the lines of its kinematic family (±2.5 lines,
//               ± its slip tolerance) in its domain at every point, where the signature
//               residual is Σ(a_m − a_s)² / Σ a_m² over those lines alone (calibration's
//               misfit elsewhere, e.g. of mesh harmonics a foreign gearbox puts elsewhere,
//               neither hides nor helps it). A hypothesis is reported when, on half B,
//                 (a) its signature residual with its term is at most (1 − min_improvement)
//                     × the calibrated one — it explains a significant part of what
//                     calibration alone left in its own lines, on data it was not fitted to;
//                 (b) its lines are significant there (locate.hpp's evidence ≥ min_evidence);
//                 (c) it improved half A's signature too and does not raise half B's total
//                     residual (the contract's sum, not clipped to 1) by more than 2 %;
//               confidence: the posterior weight of its Bayesian information criterion
//               on half B's signature residual, BIC = n·ln(residual) + k·ln(n) (n its
//               significant lines, k its parameter count), against calibration alone and
//               every other modelled candidate; reported effects are ordered by it, and a
//               further effect is reported only if its lines are not mostly (> 50 %) those
//               of one already reported;
//  8. final   — the calibrated ROM with the reported effects over the full window:
//               fit_after, residual_after. Publishes.
// A recording that differs from the model only by parameter drift therefore ends with
// no reported effect: calibration removes the drift, and no term improves what is left
// on the hold-out half.
//
// Memory: start() and step() allocate (analysis buffers, the dynamics model per
// simulation): a low-priority worker thread, never the real-time loop. The summary is
// fixed-size and trivially copyable.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "model/calibration/calibrator.hpp"
#include "model/diagnosis/analysis.hpp"
#include "model/diagnosis/effect_model.hpp"
#include "model/diagnosis/locate.hpp"
#include "model/diagnosis/signatures.hpp"
#include "model/diagnosis/speed_tracking.hpp"
#include "model/dsp/mesh_features.hpp"

namespace model::diagnosis {

inline constexpr std::size_t kPoints = calibration::kMeasurementPoints;

struct DiagnoserConfig {
  AnalysisConfig analysis{};
  LocateConfig locate{};
  CatalogueConfig catalogue{};
  SpeedTrackingConfig speed{};
  dsp::FeatureConfig features{};  // the calibrator's features (mesh orders filled by it)
  // `drivetwin calibrate`'s calibration: the default space (empty here), identification,
  // priors, its rounds and its fit budget per round.
  calibration::CalibratorConfig calibration = [] {
    model::calibration::CalibratorConfig c;
    c.trust_region.max_evaluations = model::calibration::kDefaultFitEvaluations;
    return c;
  }();
  std::size_t max_candidates =
      3;  // hypotheses refitted (and as many bearings read in the spectrum)
  std::size_t fit_evaluations = 10;           // per candidate, probes included
  std::size_t recalibration_evaluations = 0;  // calibrator with the effect on (0: not run)
  double min_improvement = 0.25;              // [-] of the calibrated hold-out signature residual
  double settle_s = 0.5;                      // [s] simulated and discarded per simulation
  std::size_t min_revolutions = 64;  // [-] reference revolutions the analysis needs at least
  std::size_t fit_revolutions = 64;  // [-] at least, per fit evaluation
  std::size_t plot_points = 1200;    // per spectrum trace of the report
};

/// The recording handed to the diagnosis (samples referenced, not copied: keep them
/// alive until the run has finished).
struct DiagnosisInput {
  double sample_rate_hz = 0.0;  // [Hz]
  std::array<const double*, kPoints>
      points{};                        // [m/s²] the drivetrain's measurement points, in order
  std::size_t samples = 0;             // per channel
  std::vector<double> tacho_pulses_s;  // [s] once-per-revolution instants; empty: none
  std::string tacho_shaft;             // shaft the tacho is on ("" : the reference shaft)
  double rotor_speed_rpm = 0.0;        // [rpm] nominal (the bundle's operating point)
  double input_torque_nm = 0.0;        // [N·m]
};

enum class DiagnosisStatus : std::uint8_t {
  kOk,
  kBadInput,          // missing channel, non-finite or flat samples, bad rate
  kTooShort,          // fewer revolutions than the analysis needs
  kNoSpeed,           // no usable speed (tacho, mesh line or operating point)
  kSimulationFailed,  // the dynamics model could not produce a waveform
  kCancelled,
};
const char* to_string(DiagnosisStatus status);

enum class DiagnosisStage : std::uint8_t {
  kIdle,
  kSpeed,
  kAnalyse,
  kCalibrate,
  kSimulate,
  kLocate,
  kRefit,
  kDecide,
  kFinal,
  kDone
};

/// A spectrum as drawn in a report: line maxima over equal frequency bins.
struct SpectrumTrace {
  std::vector<double> hz;
  std::vector<double> amplitude;
};

struct PointSpectra {
  std::string channel;
  SpectrumTrace recorded, before, calibrated, after;  // order spectra in Hz at the mean speed
  SpectrumTrace envelope_recorded, envelope_calibrated, envelope_after;  // modulation spectra
  KurtogramBand band;                                                    // envelope band
  std::vector<std::pair<std::string, double>>
      shaft_kurtosis;        // difference-signal kurtosis per shaft (recording)
  WaveformStatistics stats;  // recording
};

struct MismatchEntry {
  std::string channel;
  FeatureDomain domain = FeatureDomain::kSpectrum;
  double band_lo_hz = 0.0, band_hi_hz = 0.0;
  std::vector<double> peaks_hz;
  std::string signature;
  double share = 0.0;     // of the channel's unexplained excess in its domain
  bool kinematic = true;  // a kinematic family (or a resonance, an impulsive average) names it
};

struct CandidateResult {
  std::size_t hypothesis = 0;  // index into the catalogue
  Effect effect = Effect::kToothCrack;
  std::string location;
  std::string explanation;
  double prior_score = 0.0;  // locate.hpp's ranking score
  bool modelled = false;     // the dynamics model could switch its term on
  std::vector<std::pair<std::string, double>> parameters;  // fitted
  EffectSetting setting;                                   // fitted, for the final simulation
  double residual_fit_calibrated = 0.0, residual_fit_effect = 0.0;          // half A
  double residual_holdout_calibrated = 0.0, residual_holdout_effect = 0.0;  // half B
  // The guard against a fit that spoils the rest of the spectrum (half B): the total
  // residual line by line, or, for an impact train (envelope domain: slip makes it
  // non-periodic, its raw-spectrum lines a continuum the model can only match in power), the
  // same sum over the power of 1/12-octave bands; both not clipped to 1.
  double guard_holdout_calibrated = 0.0, guard_holdout_effect = 0.0;
  bool guard_in_bands = false;
  double signature_fit_calibrated = 0.0, signature_fit_effect = 0.0;          // half A, its lines
  double signature_holdout_calibrated = 0.0, signature_holdout_effect = 0.0;  // half B, its lines
  double holdout_evidence = 0.0;  // Σ w·(m/n)² of its significant lines on half B
  std::size_t lines = 0;          // its significant lines on half B (n of the BIC)
  std::size_t evaluations = 0;
  bool accepted = false;
  double confidence = 0.0;
  std::string verdict;  // why it was or was not reported
};

/// Everything the reports show; valid after step() returned kFinished (owner thread).
struct DiagnosisReport {
  std::string drivetrain;
  double rotor_speed_rpm = 0.0, input_torque_nm = 0.0, reference_hz = 0.0;
  std::string reference_shaft;
  std::string speed_source;                       // "tacho", "mesh line", "operating point"
  double speed_min_hz = 0.0, speed_max_hz = 0.0;  // reference shaft over the recording
  std::size_t revolutions = 0, half_revolutions = 0;
  calibration::PointIndicators fit_before{}, fit_calibrated{}, fit_after{};
  double residual_before = 1.0, residual_calibrated = 1.0, residual_after = 1.0;
  DynamicsParameters parameters_before{}, parameters_calibrated{}, parameters_after{};
  std::size_t calibration_evaluations = 0;
  std::vector<MismatchEntry> mismatch;
  std::vector<HypothesisScore> ranking;     // locate's, best first (the first 16)
  std::vector<CandidateResult> candidates;  // in the order refitted (prior score)
  std::vector<std::size_t> missing;         // indices into candidates, most likely first
  std::vector<PointSpectra> spectra;
  DiagnosisStatus status = DiagnosisStatus::kOk;
  std::string message;  // when status != kOk
};

/// The fixed-size result read_result() returns.
struct DiagnosisSummary {
  static constexpr std::size_t kMaxReported = 4;
  struct Entry {
    Effect effect = Effect::kToothCrack;
    std::array<char, 24> location{};
    double confidence = 0.0;
    std::array<double, kMaxEffectParameters> parameters{};
  };
  std::uint32_t generation = 0;
  bool finished = false, cancelled = false;
  DiagnosisStatus status = DiagnosisStatus::kOk;
  DiagnosisStage stage = DiagnosisStage::kIdle;
  calibration::PointIndicators fit_before{}, fit_calibrated{}, fit_after{};
  double residual_before = 1.0, residual_calibrated = 1.0, residual_after = 1.0;
  DynamicsParameters calibrated{};
  std::size_t reported = 0;
  std::array<Entry, kMaxReported> effects{};
};

static_assert(std::is_trivially_copyable_v<DiagnosisSummary>);

enum class DiagnosisStep : std::uint8_t { kIdle, kRunning, kFinished, kCancelled, kFailed };

class Diagnoser {
 public:
  /// @param drivetrain outlives the diagnoser
  /// @param simulator  the dynamics model with its effect terms (outlives the diagnoser)
  Diagnoser(const Drivetrain& drivetrain, EffectSimulator& simulator,
            const DiagnoserConfig& config = {});
  ~Diagnoser();

  /// Begins a diagnosis of `input` (validated here: a bad input fails the first step).
  void start(const DiagnosisInput& input);
  /// One bounded piece of work; kRunning until the run ends.
  DiagnosisStep step();
  /// Requests the run to stop at the next step() (owning thread).
  void cancel() { cancel_requested_ = true; }
  /// The summary as of the last step (finished = the run ended); false before the
  /// first step of a run. Owning thread; trivially copyable for a mailbox.
  bool read_result(DiagnosisSummary& out) const {
    if (!stepped_) return false;
    out = summary_;
    return true;
  }

  DiagnosisStage stage() const { return stage_; }
  const DiagnosisReport& report() const { return report_; }
  const Catalogue& catalogue() const { return catalogue_; }
  /// Model evaluations so far (calibration, simulations, refits).
  std::size_t simulations() const { return simulations_; }

 private:
  struct Work;
  DiagnosisStep fail(DiagnosisStatus status, std::string message);
  DiagnosisStep finish();
  void publish();
  bool step_speed();
  bool step_analyse();
  bool step_calibrate();
  bool step_simulate();
  void step_locate();
  bool step_refit();
  void step_decide();
  bool step_final();

  const Drivetrain& drivetrain_;
  EffectSimulator& simulator_;
  DiagnoserConfig config_;
  Catalogue catalogue_;
  std::unique_ptr<Work> work_;
  DiagnosisReport report_;
  DiagnosisStage stage_ = DiagnosisStage::kIdle;
  bool cancel_requested_ = false;
  DiagnosisSummary summary_{};
  std::uint32_t generation_ = 0;  // +1 per summary, across runs
  bool stepped_ = false;          // a step of the current run has made a summary
  std::size_t simulations_ = 0;
};

}  // namespace model::diagnosis
