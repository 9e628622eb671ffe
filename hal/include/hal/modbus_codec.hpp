#pragma once
// Modbus register encoding and decoding: pure functions, no libmodbus types.
// Used by the SCADA client (controller registers → quantities) and by the
// results server (TwinResults → the register image of hal/README.md, map v1).
//
// Word order: a 32-bit value occupies two 16-bit registers. kHighWordFirst
// ("ABCD", the Modbus convention and the default) puts the most significant
// word at the lower address; kLowWordFirst ("CDAB") the least significant.
// Bytes inside a register are always big-endian on the wire (libmodbus gives
// us host-order uint16_t per register).
//
// Thread context: pure; safe on any thread, no allocation.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

#include "hal/results_sink.hpp"
#include "hal/scada_source.hpp"

namespace hal {

enum class RegisterFunction : std::uint8_t { kHolding, kInput };  // FC 03 / FC 04
enum class RegisterType : std::uint8_t { kInt16, kUInt16, kInt32, kUInt32, kFloat32 };
enum class WordOrder : std::uint8_t { kHighWordFirst, kLowWordFirst };

constexpr std::size_t register_count(RegisterType t) {
  return (t == RegisterType::kInt16 || t == RegisterType::kUInt16) ? 1 : 2;
}

/// Where and how one value lives in the controller's registers.
/// value [unit] = raw × scale + offset
struct RegisterSpec {
  std::uint16_t address = 0;  // 0-based protocol address
  RegisterFunction function = RegisterFunction::kHolding;
  RegisterType type = RegisterType::kUInt16;
  WordOrder word_order = WordOrder::kHighWordFirst;
  double scale = 1.0;   // [unit/LSB]
  double offset = 0.0;  // [unit]
};

/// Decodes `regs` (register_count(spec.type) registers starting at spec.address).
/// @return the scaled value, or nullopt if too few registers were given, the
///         float is NaN/Inf, or the scale is not finite.
std::optional<double> decode_register(const RegisterSpec& spec, const std::uint16_t* regs,
                                      std::size_t n);

/// Encodes `value` into `regs` (inverse of decode_register; integers rounded to nearest).
/// @return false if n is too small or the value does not fit the type (nothing written).
bool encode_register(const RegisterSpec& spec, double value, std::uint16_t* regs, std::size_t n);

bool parse_register_type(std::string_view s,
                         RegisterType& out);  // "int16", "uint16", "int32", "uint32", "float32"
bool parse_word_order(std::string_view s,
                      WordOrder& out);  // "high_first"/"abcd", "low_first"/"cdab"
bool parse_register_function(std::string_view s, RegisterFunction& out);  // "holding", "input"
const char* to_string(RegisterType t);
const char* to_string(WordOrder w);
const char* to_string(RegisterFunction f);

/// The controller's registers the SCADA client polls: one entry per quantity used.
struct ScadaRegister {
  ScadaQuantity quantity = ScadaQuantity::kWindSpeed;
  RegisterSpec spec;
};
struct ScadaRegisterMap {
  std::array<ScadaRegister, kScadaQuantityCount> entries{};
  std::size_t count = 0;
  /// Validity register (optional): a uint16 whose bit k set means quantity k is
  /// invalid according to the controller.
  std::optional<RegisterSpec> invalid_mask;
};

/// One Modbus read transaction covering several entries.
struct ReadBlock {
  RegisterFunction function = RegisterFunction::kHolding;
  std::uint16_t start = 0;
  std::uint16_t count = 0;  // ≤ kMaxReadRegisters
};
inline constexpr std::uint16_t kMaxReadRegisters = 125;  // Modbus limit for FC 03/04
inline constexpr std::size_t kMaxReadBlocks = kScadaQuantityCount + 1;

/// Plans the fewest reads covering every entry of `map` (entries merged when a
/// block stays within kMaxReadRegisters and the hole between them ≤ max_hole).
/// @return number of blocks written to `out`.
std::size_t plan_reads(const ScadaRegisterMap& map, std::uint16_t max_hole,
                       std::array<ReadBlock, kMaxReadBlocks>& out);

/// Checks a map: addresses + width within 0..65535, finite non-zero scales, no
/// two entries for one quantity, no overlapping registers within one function.
/// @return nullopt if good, else the index of the first bad entry
///         (count for the invalid_mask register).
std::optional<std::size_t> validate_map(const ScadaRegisterMap& map);

// ---- The results register map (server side), version 1 --------------------
// Layout (0-based addresses, same image served as holding (FC 03) and input
// (FC 04) registers; 32-bit values in the server's word order, float32 = IEEE 754):
inline constexpr std::uint16_t kResultsMapVersion = 1;
namespace results_reg {
inline constexpr std::uint16_t kMapVersion = 0;       // uint16: kResultsMapVersion
inline constexpr std::uint16_t kStatusWord = 1;       // uint16: StatusBit
inline constexpr std::uint16_t kFaultWord = 2;        // uint16
inline constexpr std::uint16_t kCalibrationWord = 3;  // uint16
inline constexpr std::uint16_t kSequence = 4;         // uint32 (4-5)
inline constexpr std::uint16_t kStampS = 6;           // uint32 (6-7) [s] loop time of the results
inline constexpr std::uint16_t kRotorTorque = 8;      // float32 [N·m]
inline constexpr std::uint16_t kRotorSpeed = 10;      // float32 [rpm]
inline constexpr std::uint16_t kWindSpeed = 12;       // float32 [m/s]
inline constexpr std::uint16_t kHssSpeed = 14;        // float32 [rpm]
inline constexpr std::uint16_t kCalibrationResidual = 16;  // float32 [-]
inline constexpr std::uint16_t kComponents =
    20;  // per component c: 20 + 6c: load, damage, rul_h (float32 each)
inline constexpr std::uint16_t kComponentStride = 6;
inline constexpr std::uint16_t kIndicators =
    kComponents +
    kComponentStride * static_cast<std::uint16_t>(kResultComponentCount);  // float32 each
inline constexpr std::uint16_t kCommands =
    kIndicators + 2 * static_cast<std::uint16_t>(
                          kResultIndicatorCount);  // 16 command registers (writable if configured)
inline constexpr std::uint16_t kCommandCount = 16;
inline constexpr std::uint16_t kCount = kCommands + kCommandCount;  // total registers in the image
}  // namespace results_reg

using ResultsImage = std::array<std::uint16_t, results_reg::kCount>;

/// Fills the read-only part of the image from `results` (command registers untouched).
void encode_results(const TwinResults& results, WordOrder order, ResultsImage& image);

}  // namespace hal
