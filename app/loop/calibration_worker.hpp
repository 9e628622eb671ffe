#pragma once
// The calibration thread (low priority: SCHED_IDLE by default, app/run/threads.hpp).
//
// For every gap-free, steady CMS window the RT thread hands over (Mailboxes::windows_full):
//  1. the measured features of both points (order-tracked mesh tones and RMS,
//     model/dsp/mesh_features.hpp) at the window's high-speed shaft speed;
//  2. the paper's indicators f1/f2/f3 of the running parameters against them, from this
//     thread's own model instance at the window's operating point (the dynamics ROM via
//     model::calibration::DynamicsSimulator — never the RT thread's ROM);
//  3. when an indicator exceeds its threshold: a calibration (model::calibration::
//     Calibrator, warm-started from the previous one), stepped here and cancelled at once
//     when the twin stops; if the result improves on the running parameters, a new ROM is
//     built here (build_rom(drivetrain, parameters, settings): same step and cut-off as the
//     loop's) and offered to the RT thread (Mailboxes::rom), which adopts it at a cycle
//     boundary after its start transient has settled; the ROM it replaced comes back here
//     to be freed. The parameters are saved (calibration_store.hpp) so that a restart runs
//     the calibrated model;
//  4. when the calibration cannot reach the thresholds, the mismatch is one the parameters
//     cannot explain: the missing-physics diagnosis runs on the window (model::diagnosis::
//     Diagnoser, stepped here like the calibrator, at most once per `diagnosis_interval_s`),
//     its summary is published (Mailboxes::diagnosis) and logged; a MismatchHook set by the
//     application replaces it.
// Then the window goes back to the RT thread (windows_free).
//
// Thread context: construct on the control thread (allocates the simulator, calibrator and
// extractor); run() is the thread body; request_stop() from any thread. This thread may
// allocate (the dynamics simulator does per evaluation): it is not real-time.

#include <array>
#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "loop/events.hpp"
#include "loop/mailbox.hpp"
#include "loop/twin.hpp"
#include "model/calibration/calibrator.hpp"
#include "model/calibration/dynamics_simulator.hpp"
#include "model/diagnosis/diagnoser.hpp"
#include "model/diagnosis/effect_model.hpp"
#include "model/drivetrain/description.hpp"
#include "model/drivetrain/kinematics.hpp"
#include "model/dsp/mesh_features.hpp"
#include "model/dynamics/rom.hpp"

namespace app::loop {

/// The calibration's variables (config key calibration.space).
enum class WorkerSpace {
  kStandard,  // model::calibration::default_space: what `drivetwin calibrate` fits
  kPaper,     // the paper's 8 (CalibrationSpace::paper)
};

struct CalibrationWorkerSettings {
  model::calibration::CalibrationMethod method =
      model::calibration::CalibrationMethod::kTrustRegion;
  WorkerSpace space = WorkerSpace::kStandard;
  std::size_t max_evaluations = 30;        // [-] trust-region budget of a fit round
  model::dynamics::RomSettings rom{};      // the loop's ROM step and cut-off
  std::string state_file;                  // calibrated parameters ("" = not saved)
  bool diagnosis = true;                   // diagnose a mismatch calibration cannot remove
  double diagnosis_interval_s = 3600.0;    // [s] of loop time between two diagnoses
  std::int64_t idle_poll_ns = 20'000'000;  // [ns] how often an idle thread looks for work
};

/// What the missing-physics diagnosis hook receives when calibration cannot fit.
struct Mismatch {
  const CmsWindow& window;
  const std::array<model::dsp::PointFeatures, kSnapshotPoints>& measured;
  const model::calibration::CalibrationResult& result;
  std::uint32_t generation;
};
/// Called on the calibration thread; may allocate and take its time (the window is
/// held until it returns). Return true when it produced a better model itself (none does
/// yet: the online diagnosis API of issue 14 will).
using MismatchHook = std::function<bool(const Mismatch&)>;

class CalibrationWorker {
 public:
  /// @param parameters the parameters the loop's ROM was built with (persisted or the
  ///        description's).
  CalibrationWorker(const model::Drivetrain& drivetrain,
                    const model::DynamicsParameters& parameters,
                    const CalibrationWorkerSettings& settings, Mailboxes& mailboxes,
                    std::uint32_t generation);

  void run();
  void request_stop() { stop_.store(true, std::memory_order_relaxed); }
  void set_mismatch_hook(MismatchHook hook) { hook_ = std::move(hook); }
  /// Where this thread's formatted lines go (the diagnosis's findings); not the RT path.
  void set_note(std::function<void(const std::string&)> note) { note_ = std::move(note); }
  /// Events from this thread (its own queue; the log thread reads it).
  Queue<Event, 64>& events() { return events_; }
  const model::DynamicsParameters& parameters() const { return parameters_; }

 private:
  void process(CmsWindow& window);
  void emit(const CmsWindow& w, EventCode code, std::int32_t a = 0, double b = 0.0);
  bool calibrate(const CmsWindow& window,
                 const std::array<model::dsp::PointFeatures, kSnapshotPoints>& measured,
                 const std::vector<double>& pulses_s);
  void diagnose(const CmsWindow& window, const std::vector<double>& pulses_s);
  void reclaim_roms();

  model::Drivetrain drivetrain_;
  model::Kinematics kinematics_;
  model::DynamicsParameters parameters_;
  std::optional<model::DynamicsParameters> previous_;
  CalibrationWorkerSettings settings_;
  Mailboxes& mail_;
  std::unique_ptr<model::calibration::DynamicsSimulator> simulator_;
  std::unique_ptr<model::calibration::Calibrator> calibrator_;
  std::unique_ptr<model::dsp::FeatureExtractor> features_;
  CalibrationStatus status_{};
  MismatchHook hook_;
  std::function<void(const std::string&)> note_;
  std::unique_ptr<model::diagnosis::RomEffectSimulator> effects_;
  std::unique_ptr<model::diagnosis::Diagnoser> diagnoser_;
  std::int64_t last_diagnosis_ns_ = 0;
  bool diagnosed_ = false;
  Queue<Event, 64> events_;
  std::atomic<bool> stop_{false};
};

/// Saves / loads calibrated parameters crash-safely (write .tmp, fsync, rename, fsync the
/// folder; a CRC over the text). The file (version 2): "# drivetwin-calibration 2",
/// "# generation N", then the description's [dynamics] table with every key
/// (app/config/drivetrain_file.hpp). load() reads it, or a version-1 file (the paper's 8
/// variables), over `base` (the description's parameters: a key the file does not give
/// keeps base's value); std::nullopt when the file is missing; an error message (and
/// std::nullopt) when it is corrupt or holds a value out of its range.
bool save_calibration(const std::string& file, const model::DynamicsParameters& p,
                      std::uint32_t generation, std::string* error);
std::optional<model::DynamicsParameters> load_calibration(const std::string& file,
                                                          const model::DynamicsParameters& base,
                                                          std::uint32_t* generation,
                                                          std::string* error);

}  // namespace app::loop
