// Fuzz the Modbus register codec: decode of arbitrary registers under arbitrary
// specs, encode∘decode identity for integer types with unit scale, read
// planning of arbitrary maps (every entry covered by exactly one read within
// the protocol's 125-register limit), and the results image encoder.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "hal/modbus_codec.hpp"

namespace {

struct Bytes {
  const std::uint8_t* p;
  std::size_t n;
  std::uint8_t u8() { return n ? (--n, *p++) : 0; }
  std::uint16_t u16() { return static_cast<std::uint16_t>(u8() << 8 | u8()); }
  double f64() {
    std::uint64_t u = 0;
    for (int i = 0; i < 8; ++i) u = u << 8 | u8();
    double d;
    std::memcpy(&d, &u, sizeof d);
    return d;
  }
};

hal::RegisterSpec spec(Bytes& b) {
  hal::RegisterSpec s;
  s.address = b.u16();
  s.function = (b.u8() & 1) ? hal::RegisterFunction::kInput : hal::RegisterFunction::kHolding;
  s.type = static_cast<hal::RegisterType>(b.u8() % 5);
  s.word_order = (b.u8() & 1) ? hal::WordOrder::kLowWordFirst : hal::WordOrder::kHighWordFirst;
  return s;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Bytes b{data, size};
  // 1. decode / encode
  hal::RegisterSpec s = spec(b);
  const std::uint16_t regs[2] = {b.u16(), b.u16()};
  if (const auto v = hal::decode_register(s, regs, 2)) {
    if (!std::isfinite(*v)) std::abort();
    std::uint16_t back[2] = {0, 0};
    if (s.type != hal::RegisterType::kFloat32) {
      if (!hal::encode_register(s, *v, back, 2)) std::abort();
      if (back[0] != regs[0] || (hal::register_count(s.type) == 2 && back[1] != regs[1]))
        std::abort();
    }
  }
  s.scale = b.f64();
  s.offset = b.f64();
  if (const auto v = hal::decode_register(s, regs, 2))
    if (!std::isfinite(*v)) std::abort();
  std::uint16_t out[2];
  (void)hal::encode_register(s, b.f64(), out, 2);

  // 2. read planning
  hal::ScadaRegisterMap map;
  map.count = b.u8() % (map.entries.size() + 1);
  for (std::size_t i = 0; i < map.count; ++i) {
    map.entries[i].quantity = static_cast<hal::ScadaQuantity>(i);
    map.entries[i].spec = spec(b);
  }
  if (b.u8() & 1) map.invalid_mask = spec(b);
  if (!hal::validate_map(map)) {
    std::array<hal::ReadBlock, hal::kMaxReadBlocks> blocks{};
    const std::size_t n = hal::plan_reads(map, b.u8(), blocks);
    for (std::size_t i = 0; i < map.count; ++i) {
      const auto& e = map.entries[i].spec;
      int covering = 0;
      for (std::size_t k = 0; k < n; ++k)
        if (blocks[k].function == e.function && e.address >= blocks[k].start &&
            e.address + hal::register_count(e.type) <=
                std::size_t{blocks[k].start} + blocks[k].count)
          ++covering;
      if (covering != 1) std::abort();
    }
    for (std::size_t k = 0; k < n; ++k)
      if (blocks[k].count == 0 || blocks[k].count > hal::kMaxReadRegisters) std::abort();
  }

  // 3. results image
  // 3. a value put into a register image reads back (or is refused) whatever it is
  float f = 0.0f;
  std::memcpy(&f, data, std::min(size, sizeof(float)));
  hal::RegisterImage img;
  img.count = static_cast<std::uint16_t>(b.u16() % (hal::kMaxImageRegisters + 1));
  const auto address = static_cast<std::uint16_t>(b.u16() % hal::kMaxImageRegisters);
  const hal::WordOrder order =
      (b.u8() & 1) ? hal::WordOrder::kLowWordFirst : hal::WordOrder::kHighWordFirst;
  if (hal::put_register(img, address, hal::RegisterType::kFloat32, order, static_cast<double>(f))) {
    if (std::size_t{address} + 2 > img.count) std::abort();  // wrote outside the image
    hal::RegisterSpec spec;
    spec.type = hal::RegisterType::kFloat32;
    spec.word_order = order;
    const auto back = hal::decode_register(spec, &img.words[address], 2);
    if (!back || *back != static_cast<double>(f)) std::abort();
  }
  return 0;
}
