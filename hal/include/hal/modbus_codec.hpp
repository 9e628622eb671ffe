#pragma once
// Modbus register encoding and decoding: pure functions, no libmodbus types.
// Used by the SCADA client (controller registers → quantities) and by the
// application when it fills the results register image (its register map).
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

/// Writes `value` as `type` (word order `order`, scale 1, offset 0) at `address` of `image`.
/// @return false (nothing written) when it does not fit the type or the image's count.
bool put_register(RegisterImage& image, std::uint16_t address, RegisterType type, WordOrder order,
                  double value);

}  // namespace hal
