// Modbus register codec: see hal/modbus_codec.hpp and hal/README.md ("Results register map").
#include "hal/modbus_codec.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace hal {
namespace {

std::uint32_t join(const std::uint16_t* r, WordOrder order) {
  const std::uint32_t a = r[0];
  const std::uint32_t b = r[1];
  return order == WordOrder::kHighWordFirst ? (a << 16) | b : (b << 16) | a;
}

void split(std::uint32_t v, WordOrder order, std::uint16_t* r) {
  const auto hi = static_cast<std::uint16_t>(v >> 16);
  const auto lo = static_cast<std::uint16_t>(v & 0xFFFF);
  r[0] = order == WordOrder::kHighWordFirst ? hi : lo;
  r[1] = order == WordOrder::kHighWordFirst ? lo : hi;
}

std::uint32_t float_bits(float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

}  // namespace

std::optional<double> decode_register(const RegisterSpec& spec, const std::uint16_t* regs,
                                      std::size_t n) {
  if (regs == nullptr || n < register_count(spec.type) || !std::isfinite(spec.scale) ||
      !std::isfinite(spec.offset))
    return std::nullopt;
  double raw = 0.0;
  switch (spec.type) {
    case RegisterType::kInt16:
      raw = static_cast<double>(static_cast<std::int16_t>(regs[0]));
      break;
    case RegisterType::kUInt16:
      raw = static_cast<double>(regs[0]);
      break;
    case RegisterType::kInt32:
      raw = static_cast<double>(static_cast<std::int32_t>(join(regs, spec.word_order)));
      break;
    case RegisterType::kUInt32:
      raw = static_cast<double>(join(regs, spec.word_order));
      break;
    case RegisterType::kFloat32: {
      const std::uint32_t u = join(regs, spec.word_order);
      float f;
      std::memcpy(&f, &u, sizeof f);
      if (!std::isfinite(f)) return std::nullopt;
      raw = static_cast<double>(f);
      break;
    }
  }
  const double v = raw * spec.scale + spec.offset;
  if (!std::isfinite(v)) return std::nullopt;
  return v;
}

bool encode_register(const RegisterSpec& spec, double value, std::uint16_t* regs, std::size_t n) {
  if (regs == nullptr || n < register_count(spec.type) || !std::isfinite(value) ||
      !std::isfinite(spec.scale) || spec.scale == 0.0 || !std::isfinite(spec.offset))
    return false;
  const double raw = (value - spec.offset) / spec.scale;
  auto fits = [&](double lo, double hi) {
    return std::isfinite(raw) && std::round(raw) >= lo && std::round(raw) <= hi;
  };
  switch (spec.type) {
    case RegisterType::kInt16:
      if (!fits(-32768.0, 32767.0)) return false;
      regs[0] = static_cast<std::uint16_t>(static_cast<std::int16_t>(std::lround(raw)));
      return true;
    case RegisterType::kUInt16:
      if (!fits(0.0, 65535.0)) return false;
      regs[0] = static_cast<std::uint16_t>(std::lround(raw));
      return true;
    case RegisterType::kInt32:
      if (!fits(-2147483648.0, 2147483647.0)) return false;
      split(static_cast<std::uint32_t>(static_cast<std::int32_t>(std::llround(raw))),
            spec.word_order, regs);
      return true;
    case RegisterType::kUInt32:
      if (!fits(0.0, 4294967295.0)) return false;
      split(static_cast<std::uint32_t>(std::llround(raw)), spec.word_order, regs);
      return true;
    case RegisterType::kFloat32: {
      if (!std::isfinite(raw) ||
          std::fabs(raw) > static_cast<double>(std::numeric_limits<float>::max()))
        return false;
      split(float_bits(static_cast<float>(raw)), spec.word_order, regs);
      return true;
    }
  }
  return false;
}

bool parse_register_type(std::string_view s, RegisterType& out) {
  if (s == "int16") {
    out = RegisterType::kInt16;
  } else if (s == "uint16") {
    out = RegisterType::kUInt16;
  } else if (s == "int32") {
    out = RegisterType::kInt32;
  } else if (s == "uint32") {
    out = RegisterType::kUInt32;
  } else if (s == "float32") {
    out = RegisterType::kFloat32;
  } else {
    return false;
  }
  return true;
}

bool parse_word_order(std::string_view s, WordOrder& out) {
  if (s == "high_first" || s == "abcd") {
    out = WordOrder::kHighWordFirst;
  } else if (s == "low_first" || s == "cdab") {
    out = WordOrder::kLowWordFirst;
  } else {
    return false;
  }
  return true;
}

bool parse_register_function(std::string_view s, RegisterFunction& out) {
  if (s == "holding") {
    out = RegisterFunction::kHolding;
  } else if (s == "input") {
    out = RegisterFunction::kInput;
  } else {
    return false;
  }
  return true;
}

const char* to_string(RegisterType t) {
  switch (t) {
    case RegisterType::kInt16:
      return "int16";
    case RegisterType::kUInt16:
      return "uint16";
    case RegisterType::kInt32:
      return "int32";
    case RegisterType::kUInt32:
      return "uint32";
    case RegisterType::kFloat32:
      return "float32";
  }
  return "?";
}
const char* to_string(WordOrder w) {
  return w == WordOrder::kHighWordFirst ? "high_first" : "low_first";
}
const char* to_string(RegisterFunction f) {
  return f == RegisterFunction::kHolding ? "holding" : "input";
}

std::size_t plan_reads(const ScadaRegisterMap& map, std::uint16_t max_hole,
                       std::array<ReadBlock, kMaxReadBlocks>& out) {
  struct Span {
    RegisterFunction function;
    std::uint32_t start;
    std::uint32_t end;  // exclusive
  };
  std::array<Span, kMaxReadBlocks> spans{};
  std::size_t n = 0;
  for (std::size_t i = 0; i < map.count && i < map.entries.size(); ++i) {
    const RegisterSpec& s = map.entries[i].spec;
    spans[n++] = {s.function, s.address,
                  s.address + static_cast<std::uint32_t>(register_count(s.type))};
  }
  if (map.invalid_mask && n < spans.size()) {
    spans[n++] = {map.invalid_mask->function, map.invalid_mask->address,
                  map.invalid_mask->address +
                      static_cast<std::uint32_t>(register_count(map.invalid_mask->type))};
  }
  std::sort(spans.begin(), spans.begin() + static_cast<std::ptrdiff_t>(n),
            [](const Span& a, const Span& b) {
              return a.function != b.function ? a.function < b.function : a.start < b.start;
            });
  std::size_t blocks = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Span& s = spans[i];
    if (blocks > 0) {
      ReadBlock& last = out[blocks - 1];
      const std::uint32_t last_end = std::uint32_t{last.start} + last.count;
      const std::uint32_t new_end = std::max(last_end, s.end);
      if (last.function == s.function && s.start <= last_end + max_hole &&
          new_end - last.start <= kMaxReadRegisters) {
        last.count = static_cast<std::uint16_t>(new_end - last.start);
        continue;
      }
    }
    out[blocks++] = {s.function, static_cast<std::uint16_t>(s.start),
                     static_cast<std::uint16_t>(s.end - s.start)};
  }
  return blocks;
}

std::optional<std::size_t> validate_map(const ScadaRegisterMap& map) {
  if (map.count > map.entries.size()) return map.entries.size();
  auto bad_spec = [](const RegisterSpec& s) {
    return std::uint32_t{s.address} + register_count(s.type) > 0x10000u ||
           !std::isfinite(s.scale) || s.scale == 0.0 || !std::isfinite(s.offset);
  };
  for (std::size_t i = 0; i < map.count; ++i) {
    const RegisterSpec& s = map.entries[i].spec;
    if (bad_spec(s)) return i;
    for (std::size_t j = 0; j < i; ++j) {
      if (map.entries[j].quantity == map.entries[i].quantity) return i;
      const RegisterSpec& o = map.entries[j].spec;
      const std::uint32_t a0 = s.address, a1 = a0 + register_count(s.type);
      const std::uint32_t b0 = o.address, b1 = b0 + register_count(o.type);
      if (o.function == s.function && a0 < b1 && b0 < a1) return i;
    }
  }
  if (map.invalid_mask &&
      (bad_spec(*map.invalid_mask) || map.invalid_mask->type != RegisterType::kUInt16))
    return map.count;
  return std::nullopt;
}

bool put_register(RegisterImage& image, std::uint16_t address, RegisterType type, WordOrder order,
                  double value) {
  const std::size_t n = register_count(type);
  if (std::size_t{address} + n > image.count) return false;
  RegisterSpec spec;
  spec.address = address;
  spec.type = type;
  spec.word_order = order;
  return encode_register(spec, value, &image.words[address], n);
}

}  // namespace hal
