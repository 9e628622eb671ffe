#pragma once
// One cycle of the twin: what the real-time thread does every period (style.md §2):
//
//   1 read     SCADA (latest values and their age), keyphasor edges, CMS blocks (drained,
//              bounded per cycle) → ISO 10816-21 band values per point, calibration window
//   2 decide   the supervisor: ROM inputs (measured torque, else power, else wind; held or
//              steady-state when SCADA is stale), status and fault words, alarm
//   3 step     the ROM by its fixed steps, each step's loads into the damage accumulators;
//              a calibrated ROM handed over by the calibration thread is stepped beside the
//              running one until its start transient has decayed, then takes over (the old
//              one goes back to the builder) — no transient is ever counted as damage
//   4 write    watchdog toggle, alarm output
//   5 publish  every `publish_divisor` cycles: the Snapshot (queue + latest value), the
//              results register image; events on every change
//
// Everything is allocated in the constructor (and the members' own constructors); cycle()
// allocates nothing, takes no lock, never blocks and reads no clock: the loop passes `now`.
// Exceptions are not used after construction.
//
// Thread context: construct on the control thread at start-up; cycle() on the RT thread
// only; the accessors from the RT thread (or after it has stopped).

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "fatigue/dynamics_spectrum.hpp"
#include "hal/cms_stream.hpp"
#include "hal/digital_outputs.hpp"
#include "hal/keyphasor.hpp"
#include "hal/results_sink.hpp"
#include "hal/scada_source.hpp"
#include "loop/events.hpp"
#include "loop/mailbox.hpp"
#include "loop/snapshot.hpp"
#include "model/calibration/indicators.hpp"
#include "model/diagnosis/diagnoser.hpp"
#include "model/drivetrain/description.hpp"
#include "model/dynamics/rom.hpp"
#include "model/fatigue/damage_accumulator.hpp"
#include "model/fatigue/drivetrain_channels.hpp"
#include "results/register_map.hpp"
#include "signal/clock_mapping.hpp"
#include "signal/rom_input_shaper.hpp"
#include "supervisor/supervisor.hpp"
#include "supervisor/vibration_zones.hpp"

namespace app::loop {

/// A gap-free stretch of both measurement points' CMS samples with the operating point it
/// was taken at: what the calibration thread compares the model with. Buffers are sized
/// once at start-up; the RT thread fills them, the calibration thread reads them.
struct CmsWindow {
  std::array<std::vector<double>, kSnapshotPoints> samples;  // [m/s²] capacity = window
  std::size_t count = 0;                                     // [-] samples per point in use
  /// [s] keyphasor edges inside the window, in the window's time base (sample 0 at 0: the
  /// CMS front end's clock mapped onto the keyphasor's, app/signal/clock_mapping.hpp);
  /// capacity fixed at start-up.
  std::vector<double> pulses_s;
  std::size_t pulse_count = 0;   // [-] in use (0: no keyphasor, or no clock mapping yet)
  double sample_rate_hz = 0.0;   // [Hz]
  std::int64_t start_ns = 0;     // [ns] loop time of the first cycle of the window
  double rotor_speed_rpm = 0.0;  // [rpm] mean over the window
  double input_torque_nm = 0.0;  // [N·m] mean over the window
  double hss_hz = 0.0;           // [Hz] high-speed shaft speed (keyphasor mean, else SCADA)
};

/// What the calibration thread reports (latest value).
struct CalibrationStatus {
  std::uint32_t checks = 0;              // [-] windows compared
  std::uint32_t calibrations = 0;        // [-] calibrations finished
  std::uint32_t generation = 0;          // [-] newest model handed over (0: the configured one)
  bool fits = true;                      // the last comparison was within every threshold
  bool unfit_after_calibration = false;  // the last calibration could not reach them
  double worst_ratio = -1.0;             // [-] worst indicator / threshold of the last comparison
  std::array<std::array<double, 3>, kSnapshotPoints> f{};  // f1, f2, f3 of the last comparison
};

/// Damage per channel at the end of a RUL interval (RT → service thread).
struct IntervalRecord {
  std::int64_t stamp_ns = 0;
  double elapsed_s = 0.0;  // [s] accumulated
  std::uint32_t channel_count = 0;
  std::array<double, model::fatigue::kMaxChannels> damage{};
};

/// RUL at the p90 damage rate per channel (service thread → RT), NaN when unknown.
struct RulTable {
  std::array<float, model::fatigue::kMaxChannels> rul_low_h{};
  std::uint32_t intervals = 0;
};

/// Every mailbox the loop's threads exchange data through (one object, built at start-up).
struct Mailboxes {
  static constexpr std::size_t kWindows = 3;      // calibration windows in circulation
  static constexpr std::size_t kSnapshots = 64;   // snapshots the recorder may lag behind
  static constexpr std::size_t kEvents = 256;     // log events the log thread may lag behind
  static constexpr std::size_t kCheckpoints = 2;  // accumulator state copies in circulation

  Handover<model::dynamics::RomData> rom;                // calibration → RT; old ones back
  Queue<CmsWindow*, kWindows> windows_full;              // RT → calibration
  Queue<CmsWindow*, kWindows> windows_free;              // calibration → RT
  Latest<CalibrationStatus> calibration;                 // calibration → RT, anyone
  Latest<model::diagnosis::DiagnosisSummary> diagnosis;  // calibration thread → anyone
  Queue<Snapshot, kSnapshots> snapshots;                 // RT → recorder (trends, persistence)
  Latest<Snapshot> latest;                               // RT → anyone (servers, dashboard)
  Queue<Event, kEvents> events;                          // RT → log thread
  Queue<IntervalRecord, 8> intervals;                    // RT → service (RUL history)
  Latest<RulTable> rul;                                  // service → RT
  Queue<model::fatigue::AccumulatorState*, kCheckpoints> checkpoints_full;  // RT → persistence
  Queue<model::fatigue::AccumulatorState*, kCheckpoints> checkpoints_free;  // persistence → RT
  std::atomic<bool> persistence_failed{false};  // persistence → RT: the last save failed
};

struct TwinDevices {
  hal::ScadaSource* scada = nullptr;       // required
  hal::CmsStream* cms = nullptr;           // optional
  hal::Keyphasor* keyphasor = nullptr;     // optional
  hal::DigitalOutputs* outputs = nullptr;  // optional
  hal::ResultsSink* results = nullptr;     // optional
};

/// The settings of one twin, derived from the run configuration at start-up.
struct TwinSettings {
  std::int64_t period_ns = 1'000'000;                    // [ns] cycle period
  int rom_steps_per_cycle = 8;                           // [-]
  int publish_divisor = 100;                             // [-]
  double cms_sample_rate_hz = 25600.0;                   // [Hz]
  std::array<int, kSnapshotPoints> point_channel{0, 1};  // CMS channel id per point
  supervisor::ZoneLimits zones{};
  supervisor::SupervisorConfig supervisor{};
  bool calibration_enabled = true;
  double window_s = 6.0;                  // [s]
  double check_interval_s = 600.0;        // [s]
  double steady_speed_tolerance = 0.05;   // [-]
  double steady_torque_tolerance = 0.10;  // [-]
  double rul_interval_s = 86400.0;        // [s]
  double checkpoint_interval_s = 60.0;    // [s]
  std::uint32_t accumulator_bins = 200;   // [-]
  /// [s] the SCADA's sample period (Modbus poll period, a replay's row spacing): how the
  /// ROM's inputs are shaped between samples (app/signal/rom_input_shaper.hpp).
  double scada_period_s = 1.0;
};

class Twin {
 public:
  /// Most CMS blocks drained per cycle (the rest wait for the next: bounded work).
  static constexpr std::size_t kMaxBlocksPerCycle = 4096;
  /// Most keyphasor edges drained per cycle.
  static constexpr std::size_t kMaxEdgesPerCycle = 256;

  /// @param drivetrain, channels, rom, mailboxes, devices outlive the Twin.
  /// @param rom the model to start with (owned by the caller until handed back through
  ///        the mailbox after a calibrated model replaced it; see rom_in_use()).
  /// Throws std::runtime_error naming what is wrong (start-up only).
  Twin(const model::Drivetrain& drivetrain, const model::fatigue::ChannelSet& channels,
       const model::dynamics::RomData& rom, const TwinSettings& settings, Mailboxes& mailboxes,
       const TwinDevices& devices);

  /// Restores persisted damage before the first cycle. @return false when the state does
  /// not fit this configuration (AccumulatorState::config_hash differs).
  bool restore(const model::fatigue::AccumulatorState& state);
  /// Sets the calibration generation the persisted calibration had.
  void set_calibration_generation(std::uint16_t g) { calibration_generation_ = g; }

  /// One cycle at loop time `now`. `overran`: the previous cycle ended after its deadline;
  /// `skipped`: periods skipped since; timing of the previous cycle for the counters.
  void cycle(hal::Timestamp now);
  /// The loop's timing, recorded by the scheduler (RT thread).
  void record_timing(double wakeup_latency_us, double cycle_time_us, bool overran,
                     std::uint64_t skipped);
  /// Publishes a snapshot now (the last cycle's state), e.g. at shutdown.
  void publish(hal::Timestamp now);

  /// Calibration windows the calibration thread holds now (RT thread): a lockstep replay
  /// waits for 0 so that what the calibration hands back arrives at a reproducible cycle.
  std::size_t windows_outstanding() const;

  const model::fatigue::DamageAccumulator& accumulator() const { return *accumulator_; }
  const LoopCounters& counters() const { return counters_; }
  /// Checkpoints handed to the persistence thread, and skipped because both buffers were
  /// still being written (RT thread, or after it stopped).
  std::uint64_t checkpoints_handed_over() const { return checkpoints_handed_over_; }
  std::uint64_t checkpoints_skipped() const { return checkpoints_skipped_; }
  /// [s] accumulated time in the last checkpoint handed over.
  double last_checkpoint_elapsed_s() const { return last_checkpoint_elapsed_s_; }
  const Snapshot& last_snapshot() const { return snapshot_; }
  /// The model the RT thread runs now (after the loop stopped: to free it).
  const model::dynamics::RomData* rom_in_use() const { return rom_data_; }
  /// A replaced model the full return path has not taken yet (after the loop stopped).
  const model::dynamics::RomData* rom_not_returned() const { return pending_return_; }
  /// The ROM being settled beside the running one (after the loop stopped), or nullptr.
  const model::dynamics::RomData* rom_settling() const { return shadow_data_; }

 private:
  void drain_keyphasor(hal::Timestamp now);
  void drain_cms(hal::Timestamp now);
  void step_model(hal::Timestamp now, const supervisor::SupervisorDecision& d);
  void adopt_calibrated(const supervisor::SupervisorDecision& d);
  void collect_window(hal::Timestamp now, const supervisor::SupervisorDecision& d);
  void window_samples(std::size_t point, const hal::CmsBlock& block);
  void window_pulses();
  void abort_window(int reason);
  void emit(hal::Timestamp now, EventCode code, std::int32_t a = 0, double b = 0.0);
  void events_on_change(hal::Timestamp now, const supervisor::SupervisorDecision& d);
  void fill_snapshot(hal::Timestamp now);
  void checkpoint();

  const model::fatigue::ChannelSet& channels_;
  TwinSettings settings_;
  Mailboxes& mail_;
  TwinDevices dev_;

  // Model.
  const model::dynamics::RomData* rom_data_;
  model::dynamics::Rom rom_;
  const model::dynamics::RomData* shadow_data_ = nullptr;  // settling beside rom_
  model::dynamics::Rom shadow_;
  std::int64_t shadow_steps_left_ = 0;
  double shadow_settle_s_ = 0.0;
  const model::dynamics::RomData* pending_return_ = nullptr;  // to hand back
  bool rom_started_ = false;
  std::uint16_t calibration_generation_ = 0;
  fatigue::RomLoadConverter converter_;
  signal::RomInputShaper shaper_;        // the ROM's inputs per step
  std::uint32_t last_scada_update_ = 0;  // SCADA update count of the last sample shaped
  std::unique_ptr<model::fatigue::DamageAccumulator> accumulator_;
  model::dynamics::RomOutputs rom_out_{}, shadow_out_{};
  model::fatigue::LoadSample loads_{};
  std::array<double, model::fatigue::kMaxChannels> last_load_{};  // [MPa or N] per channel
  double hss_ratio_ = 1.0;                                        // [-] hss speed / rotor speed

  // Inputs.
  hal::ScadaData scada_{};
  hal::KeyphasorTracker keyphasor_;
  hal::KeyphasorTracker::State keyphasor_state_{};
  std::array<int, hal::kCmsMaxChannels> point_of_channel_{};  // −1: not a point
  std::array<std::uint16_t, hal::kCmsMaxChannels> last_sequence_{};
  std::array<bool, hal::kCmsMaxChannels> have_sequence_{};
  std::array<std::size_t, hal::kCmsMaxChannels> samples_per_block_{};
  std::uint64_t lost_blocks_cycle_ = 0;
  bool cms_fault_ = false;
  std::array<supervisor::VibrationZones, kSnapshotPoints> zones_{};
  supervisor::Supervisor supervisor_;
  supervisor::SupervisorDecision last_decision_{};
  hal::Status last_scada_status_ = hal::Status::kNoData;

  // Calibration window in progress.
  CmsWindow* window_ = nullptr;
  std::size_t window_capacity_ = 0;
  std::array<std::size_t, kSnapshotPoints> window_fill_{};
  double window_rpm_sum_ = 0.0, window_torque_sum_ = 0.0, window_hss_sum_ = 0.0;
  double window_rpm_min_ = 0.0, window_rpm_max_ = 0.0;
  double window_torque_min_ = 0.0, window_torque_max_ = 0.0;
  std::size_t window_cycles_ = 0, window_hss_cycles_ = 0;
  std::int64_t window_device_start_ns_ = 0;  // [ns] CMS clock of the window's first sample
  std::size_t window_edges_ = 0;             // keyphasor edges [ns, host] in window_->pulses_s
  signal::ClockMapping clock_map_;           // CMS front-end clock → keyphasor (host) clock
  hal::Timestamp next_window_{0};
  CalibrationStatus calibration_{};

  // Results.
  results::RegisterMap register_map_;
  hal::RegisterImage image_{};
  Snapshot snapshot_{};
  LoopCounters counters_{};
  std::uint64_t cycle_index_ = 0;
  std::uint32_t sequence_ = 0;
  bool watchdog_level_ = false;
  bool overrun_since_publish_ = false;
  bool rom_diverged_since_publish_ = false;
  bool queue_full_since_publish_ = false;
  bool alarm_ = false;
  std::array<VibrationZone, kSnapshotPoints> zone_{};
  hal::Timestamp next_interval_{0};
  hal::Timestamp next_checkpoint_{0};
  std::uint64_t checkpoints_handed_over_ = 0;
  std::uint64_t checkpoints_skipped_ = 0;
  double last_checkpoint_elapsed_s_ = 0.0;
  RulTable rul_{};
};

}  // namespace app::loop
