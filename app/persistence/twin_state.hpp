#pragma once
// What `drivetwin run` persists, as sections of the crash-safe state record
// (app/persistence/state_store.hpp): the damage accumulators, the RUL rate history, the
// calibration, and the lifetime damage of channels the configuration no longer has — with
// the rule that carries the lifetime damage over a change of ROM rate or channel set instead
// of stranding it.
//
// Sections (ids permanent: a retired id is never reused; a layout change bumps the section's
// version, and a reader refuses a version it does not know, naming it):
//   1 layout        the accumulator's configuration: tick [s], bins, per channel its key
//                   ("component/detail/mode"), histogram full scale and source count
//   2 accumulator   counters, per channel damage (Neumaier sum + compensation), largest
//                   overflow stress and the histogram (bins + overflow: ticks, 2^-32 rev) —
//                   only the channels and bins in use (≈ 95 KB for paper-2mw's 29 × 201)
//   3 rate history  RUL damage-rate history per channel (the ring's intervals, oldest first,
//                   the long-term sums, the damage at the last interval boundary)
//   4 calibration   the calibrated parameters (an opaque text with its format tag, written by
//                   the calibration code) and their generation
//   5 retired       lifetime damage of channels the running configuration does not have
// All little-endian (as the box and the host are): u32, u64, f64, strings as u32 length + bytes.
//
// Carry-over (restore_accumulator): the same configuration restores the state bit for bit.
// Otherwise every channel of the new configuration with the key of a saved one takes its
// damage exactly; its histogram is converted (times to the new tick, rounded with the totals
// kept exact; bins redistributed by overlap when the bins or full scale changed, assuming
// time spreads uniformly within a saved bin; the overflow at the saved largest stress). A
// channel new to the configuration starts at zero (reported); a saved channel the
// configuration lost is kept in the retired list, written back with every save (reported),
// and taken back if a later configuration has it again. Nothing accumulated is dropped.
//
// Thread context: non-real-time (allocates): start-up and the persistence thread.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "model/fatigue/damage_accumulator.hpp"
#include "model/fatigue/rul.hpp"
#include "persistence/state_store.hpp"

namespace app::persistence {

/// Section ids of the twin's state record. Permanent.
enum class TwinSection : std::uint32_t {
  kLayout = 1,
  kAccumulator = 2,
  kRateHistory = 3,
  kCalibration = 4,
  kRetired = 5,
};
inline constexpr std::uint32_t kLayoutVersion = 1;
inline constexpr std::uint32_t kAccumulatorSectionVersion = 1;
inline constexpr std::uint32_t kRateHistoryVersion = 1;
inline constexpr std::uint32_t kCalibrationVersion = 1;
inline constexpr std::uint32_t kRetiredVersion = 1;

/// "component/detail/mode" (detail omitted when empty): what identifies a channel across
/// configurations.
std::string channel_key(const model::fatigue::Channel& channel);

struct AccumulatorLayout {
  double tick_s = 0.0;  // [s]
  std::uint32_t bins = 0;
  std::vector<std::string> keys;
  std::vector<double> full_scale;           // [MPa or N]
  std::vector<std::uint32_t> source_count;  // [-]
};
AccumulatorLayout layout_of(const model::fatigue::DamageAccumulator& acc);

struct RateHistoryRecord {
  double interval_s = 0.0;         // [s]
  std::uint64_t short_window = 0;  // [-]
  struct Channel {
    std::vector<double> increments;  // oldest first
    double total_increment = 0.0;
    std::uint64_t total_intervals = 0;
    double damage_at_boundary = 0.0;  // [-] lifetime damage at the last interval boundary
  };
  std::vector<Channel> channels;  // layout order
};
/// The record of per-channel histories (`boundary` = damage at the last interval boundary).
RateHistoryRecord record_of(const std::vector<model::fatigue::DamageRateHistory>& histories,
                            const std::vector<double>& boundary);

struct CalibrationRecord {
  std::uint32_t generation = 0;
  std::string format;  // e.g. "drivetwin-calibration 1"
  std::string text;    // the parameters in that format
};

struct RetiredChannel {
  std::string key;
  double damage = 0.0;     // [-] lifetime damage when it was retired
  double elapsed_s = 0.0;  // [s] time it had accumulated
};

struct TwinState {
  AccumulatorLayout layout;
  std::unique_ptr<model::fatigue::AccumulatorState> accumulator;  // never null after decode
  std::optional<RateHistoryRecord> rate;
  std::optional<CalibrationRecord> calibration;
  std::vector<RetiredChannel> retired;
};

/// The sections of a state (layout + accumulator always; the others when present).
std::vector<StateSection> encode_twin_state(const TwinState& state);
/// Decodes a record; nullopt with `error` naming the section and what is wrong.
std::optional<TwinState> decode_twin_state(const StateRecord& record, std::string* error);

/// What restore_accumulator() did, one line per notable thing (for the log).
struct CarryOver {
  bool exact = false;        // same configuration: restored bit for bit
  std::size_t matched = 0;   // channels carried by key
  std::size_t added = 0;     // channels of the configuration the state did not have
  std::size_t retired = 0;   // saved channels the configuration does not have
  std::size_t returned = 0;  // retired channels the configuration has again
  std::vector<std::string> notes;
};

/// Restores `saved` into `acc` (which has the running configuration), carrying over a
/// change of tick, bins, full scale or channel set as described above; `retired` receives
/// the retired list to keep (saved.retired updated). The accumulator is reset first.
CarryOver restore_accumulator(const TwinState& saved, model::fatigue::DamageAccumulator& acc,
                              std::vector<RetiredChannel>& retired);

/// Restores per-channel rate histories from the record by key (layout `saved_keys` →
/// the running `keys`); a channel without a saved history starts empty. `boundary` gets each
/// channel's damage at the last interval boundary (its lifetime damage when it starts empty).
/// A record of another interval length is not used (false, histories untouched).
bool restore_rate_histories(const RateHistoryRecord& rec,
                            const std::vector<std::string>& saved_keys,
                            const std::vector<std::string>& keys,
                            std::vector<model::fatigue::DamageRateHistory>& histories,
                            std::vector<double>& boundary, std::string* note);

}  // namespace app::persistence
