#pragma once
// The results register map: which of the twin's results lives in which Modbus register.
// hal serves a register image and knows nothing of its meaning (hal/results_sink.hpp);
// this is the one declaration of the meaning, from which the image is filled every
// cycle (encode()) and the register table of the documentation is generated
// (markdown(); `drivetwin results-map`, docs/results-map.md).
//
// Layout, map version kResultsMapVersion (0-based protocol addresses; 32-bit values take two
// registers in the configured word order; float32 is IEEE 754):
//   0 ..  19   the header (kHeader below): version, status/fault words, sequence, time,
//              torque, speeds, wind, calibration
//  20 .. 133   retired (map v1's 19 fixed "reference gearbox" components); read as 0
// 134 .. 149   condition indicators (kIndicatorNames), float32 each
// 150 .. 165   command block: written by clients where the config allows, never by the twin
// 200 + 8c ..  damage channel c of the drivetrain (every gear × failure mode, every
//              bearing, per planet: model/fatigue/drivetrain_channels.hpp), c = 0 ..
//              channel_count − 1 in ChannelSet order: damage, RUL, RUL at the p90 rate,
//              load of the last cycle (float32 each). The count is at kChannelCount.
// Addresses are permanent: a later version appends and retires, never moves or reuses.
//
// Thread context: RegisterMap is built at start-up (allocates); encode() is RT-safe
// (a loop over the entries, no allocation, no locks).

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "hal/modbus_codec.hpp"
#include "hal/results_sink.hpp"
#include "model/fatigue/drivetrain_channels.hpp"

namespace app::results {

inline constexpr std::uint16_t kResultsMapVersion = 2;

/// Bits of the status word (register 1).
enum StatusBit : std::uint16_t {
  kStatusRunning = 1u << 0,   // loop running
  kStatusDegraded = 1u << 1,  // some input invalid/stale; results held or estimated
  kStatusScadaStale = 1u << 2,
  kStatusCmsFault = 1u << 3,  // CAN gaps / bus-off / silent
  kStatusKeyphasorFault = 1u << 4,
  kStatusCalibrated = 1u << 5,  // model parameters calibrated
  kStatusAlarm = 1u << 6,       // alarm relay raised
  kStatusOverrun = 1u << 7,     // a cycle overran since the last publish
};

/// Condition indicators, in register order.
inline constexpr std::size_t kIndicatorCount = 8;
inline constexpr std::array<const char*, kIndicatorCount> kIndicatorNames{
    "point1_rms_mps2", "point2_rms_mps2", "point1_kurtosis", "point2_kurtosis",
    "residual",        "fit_f1",          "fit_f2",          "fit_f3"};

/// One damage channel's results.
struct ChannelResult {
  float damage = 0.0f;     // [-] accumulated Palmgren–Miner damage
  float rul_h = 0.0f;      // [h] remaining useful life at the long-term rate
  float rul_low_h = 0.0f;  // [h] remaining useful life at the p90 rate (pessimistic)
  float load = 0.0f;       // [MPa or N] stress (gears) or equivalent load (bearings), last cycle
};

/// What the registers show: filled by the loop from its results snapshot.
struct ResultsValues {
  std::int64_t stamp_ns = 0;   // [ns] loop time of the results
  std::uint32_t sequence = 0;  // [-] publish counter
  std::uint16_t status_word = 0;
  std::uint16_t fault_word = 0;
  std::uint16_t calibration_generation = 0;
  float rotor_torque_nm = 0.0f;       // [N·m]
  float rotor_speed_rpm = 0.0f;       // [rpm]
  float wind_speed_mps = 0.0f;        // [m/s]
  float hss_speed_rpm = 0.0f;         // [rpm] from the keyphasor
  float calibration_residual = 0.0f;  // [-]
  std::array<float, kIndicatorCount> indicators{};
  std::array<ChannelResult, model::fatigue::kMaxChannels> channels{};
};

/// What a register shows.
enum class Quantity : std::uint8_t {
  kMapVersion,
  kStatusWord,
  kFaultWord,
  kCalibrationGeneration,
  kSequence,
  kStampS,
  kRotorTorque,
  kRotorSpeed,
  kWindSpeed,
  kHssSpeed,
  kCalibrationResidual,
  kChannelCount,
  kIndicator,      // index: indicator
  kCommand,        // index: command register
  kChannelDamage,  // index: channel
  kChannelRul,
  kChannelRulLow,
  kChannelLoad,
};

/// A register (or register pair) of the map.
struct RegisterEntry {
  std::uint16_t address = 0;
  hal::RegisterType type = hal::RegisterType::kUInt16;
  Quantity quantity = Quantity::kMapVersion;
  std::uint16_t index = 0;  // indicator, command or channel
  std::string name;         // stable id, e.g. "status_word", "channel.planet1.contact.ring-side"
  std::string unit;
  std::string description;
};

class RegisterMap {
 public:
  static constexpr std::uint16_t kIndicatorBase = 134;
  static constexpr std::uint16_t kCommandStart = 150;
  static constexpr std::uint16_t kCommandCount = 16;
  static constexpr std::uint16_t kChannelBase = 200;
  static constexpr std::uint16_t kChannelStride = 8;

  /// The map for the damage channels of `channels` (their names and order).
  explicit RegisterMap(const model::fatigue::ChannelSet& channels,
                       hal::WordOrder order = hal::WordOrder::kHighWordFirst);
  /// The map without damage channels (header, indicators, commands): for a server that
  /// runs before the twin knows its drivetrain (`bus probe`).
  explicit RegisterMap(hal::WordOrder order = hal::WordOrder::kHighWordFirst);

  const std::vector<RegisterEntry>& entries() const { return entries_; }
  /// Registers the image needs (one past the highest address).
  std::uint16_t register_count() const { return register_count_; }
  std::size_t channel_count() const { return channel_count_; }
  hal::WordOrder word_order() const { return order_; }

  /// Fills every read-only register of `image` from `values` (command block untouched,
  /// image.count set). Non-finite or out-of-range values are written as 0 (floats: NaN
  /// is kept, it is what a client should see for "no value"). RT-safe.
  void encode(const ResultsValues& values, hal::RegisterImage& image) const;

  /// The register table as Markdown (address, type, name, unit, description).
  std::string markdown() const;

 private:
  void build(const model::fatigue::ChannelSet* channels);
  std::vector<RegisterEntry> entries_;
  std::uint16_t register_count_ = 0;
  std::size_t channel_count_ = 0;
  hal::WordOrder order_;
};

}  // namespace app::results
