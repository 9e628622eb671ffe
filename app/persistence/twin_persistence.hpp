#pragma once
// The twin's persistence as `drivetwin run` uses it: the crash-safe two-copy store
// (state_store.hpp) holding the twin's state sections (twin_state.hpp) — damage
// accumulators, RUL rate history, a copy of the calibration, retired channels.
//
//   start-up     load(): the newest valid record (a corrupt or torn copy is reported and the
//                other used; both bad: reported, nothing loaded, the files kept for inspection),
//                carried into the running configuration (ROM rate, bins, channel set);
//                without a record, the former single-file store (accumulators.state) is taken
//                over when its configuration matches.
//   service      add_interval(): the RUL rate history (one interval of damage per channel),
//                giving the RUL at the p90 rate per channel.
//   persistence  save(): a checkpoint the RT thread copied, with the rate history and the
//                calibration file's current text, as the next generation.
//
// Thread context: non-real-time. load() before the threads start; add_interval() and save()
// from two different threads (an internal mutex guards the rate history and the retired
// list); nothing here is ever called from the RT thread.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "model/fatigue/damage_accumulator.hpp"
#include "model/fatigue/rul.hpp"
#include "persistence/state_store.hpp"
#include "persistence/twin_state.hpp"

namespace app::persistence {

struct TwinPersistenceSettings {
  std::filesystem::path state_dir;
  std::string calibration_file;  // its text is copied into every record ("" = none)
  double rul_interval_s = 86400.0;
  std::size_t rul_short_window = 30;
};

struct TwinLoad {
  bool restored = false;  // damage loaded (exactly or carried over)
  std::unique_ptr<model::fatigue::AccumulatorState> accumulator;  // for the running configuration
  std::optional<CalibrationRecord> calibration;                   // the record's copy
  std::vector<std::string> lines;  // what to log (problems as "WARN: …")
};

class TwinPersistence {
 public:
  /// @param channels, config: the running accumulator's (must outlive this object).
  TwinPersistence(const TwinPersistenceSettings& settings,
                  const model::fatigue::ChannelSet& channels,
                  const model::fatigue::AccumulatorConfig& config);

  TwinLoad load();

  /// One RUL interval ended with `damage` (lifetime, per channel). @return the RUL at the
  /// p90 damage rate per channel [h] (+inf: no damage rate yet).
  std::vector<double> add_interval(const std::vector<double>& damage);
  /// Saves `checkpoint` (the accumulator, copied at a cycle boundary) taken at loop time
  /// `now_ns`. False with `error` naming the file and the failing step.
  bool save(const model::fatigue::AccumulatorState& checkpoint, std::int64_t now_ns,
            std::string* error);

  const StateStore& store() const { return store_; }
  std::uint64_t saves() const { return saves_; }

 private:
  TwinPersistenceSettings settings_;
  const model::fatigue::ChannelSet& channels_;
  model::fatigue::AccumulatorConfig config_;
  AccumulatorLayout layout_;
  StateStore store_;
  std::mutex mutex_;
  std::vector<model::fatigue::DamageRateHistory> histories_;
  std::vector<double> boundary_;  // lifetime damage at the last interval boundary
  std::vector<RetiredChannel> retired_;
  std::uint64_t saves_ = 0;
};

}  // namespace app::persistence
