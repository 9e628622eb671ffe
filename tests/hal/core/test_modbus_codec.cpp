// Modbus register codec against register values worked out by hand
// (IEEE 754 bit patterns computed independently: 361747.0f = 0x48B0A260,
// -12.5f = 0xC1480000, 8.33f = 0x410547AE).
#include <gtest/gtest.h>

#include <cmath>

#include "hal/modbus_codec.hpp"

namespace {

using hal::RegisterSpec;
using hal::RegisterType;
using hal::WordOrder;

RegisterSpec spec(RegisterType t, WordOrder o = WordOrder::kHighWordFirst, double scale = 1.0,
                  double offset = 0.0) {
  RegisterSpec s;
  s.type = t;
  s.word_order = o;
  s.scale = scale;
  s.offset = offset;
  return s;
}

TEST(ModbusCodec, DecodesFloat32InBothWordOrders) {
  // Arrange
  const std::uint16_t abcd[2] = {0x48B0, 0xA260};
  const std::uint16_t cdab[2] = {0xA260, 0x48B0};

  // Act
  const auto hi = hal::decode_register(spec(RegisterType::kFloat32), abcd, 2);
  const auto lo =
      hal::decode_register(spec(RegisterType::kFloat32, WordOrder::kLowWordFirst), cdab, 2);

  // Assert
  ASSERT_TRUE(hi && lo);
  EXPECT_EQ(*hi, 361747.0);
  EXPECT_EQ(*lo, 361747.0);
}

TEST(ModbusCodec, AppliesScaleAndOffsetToSignedAndUnsignedIntegers) {
  // Arrange: wind 0.01 m/s per LSB; temperature (raw − 400) × 0.1 °C; int32 −2 = 0xFFFF FFFE
  const std::uint16_t wind[1] = {675};
  const std::uint16_t temp[1] = {static_cast<std::uint16_t>(-5)};  // int16 −5
  const std::uint16_t big[2] = {0xFFFF, 0xFFFE};
  const std::uint16_t u32[2] = {0x0001, 0x0000};  // 65536 high-word-first

  // Act / Assert
  EXPECT_NEAR(
      *hal::decode_register(spec(RegisterType::kUInt16, WordOrder::kHighWordFirst, 0.01), wind, 1),
      6.75, 1e-12);
  EXPECT_NEAR(*hal::decode_register(
                  spec(RegisterType::kInt16, WordOrder::kHighWordFirst, 0.1, -40.0), temp, 1),
              -40.5, 1e-12);
  EXPECT_EQ(*hal::decode_register(spec(RegisterType::kInt32), big, 2), -2.0);
  EXPECT_EQ(*hal::decode_register(spec(RegisterType::kUInt32), u32, 2), 65536.0);
  EXPECT_EQ(*hal::decode_register(spec(RegisterType::kUInt32, WordOrder::kLowWordFirst), u32, 2),
            1.0);
}

TEST(ModbusCodec, RefusesNanFloatsAndTooFewRegisters) {
  // Arrange: 0x7FC0 0000 is a quiet NaN
  const std::uint16_t nan_regs[2] = {0x7FC0, 0x0000};

  // Act / Assert
  EXPECT_FALSE(hal::decode_register(spec(RegisterType::kFloat32), nan_regs, 2));
  EXPECT_FALSE(hal::decode_register(spec(RegisterType::kInt32), nan_regs, 1));
}

TEST(ModbusCodec, EncodesTheInverseOfDecodeAndRejectsValuesThatDoNotFit) {
  // Arrange
  std::uint16_t r[2] = {0, 0};

  // Act / Assert: -12.5f low word first → C148 0000 swapped
  ASSERT_TRUE(
      hal::encode_register(spec(RegisterType::kFloat32, WordOrder::kLowWordFirst), -12.5, r, 2));
  EXPECT_EQ(r[0], 0x0000);
  EXPECT_EQ(r[1], 0xC148);
  ASSERT_TRUE(hal::encode_register(spec(RegisterType::kUInt16, WordOrder::kHighWordFirst, 0.01),
                                   6.75, r, 1));
  EXPECT_EQ(r[0], 675);
  EXPECT_FALSE(hal::encode_register(spec(RegisterType::kUInt16), -1.0, r, 1));
  EXPECT_FALSE(hal::encode_register(spec(RegisterType::kInt16), 40000.0, r, 1));
  EXPECT_FALSE(hal::encode_register(spec(RegisterType::kFloat32), std::nan(""), r, 2));
}

TEST(ModbusCodec, PlansOneReadPerContiguousRunAndSplitsFunctions) {
  // Arrange: holding 100 (f32), 102 (u16), 110 (u16); input 5 (u16)
  hal::ScadaRegisterMap map;
  auto add = [&](hal::ScadaQuantity q, std::uint16_t a, RegisterType t, hal::RegisterFunction f) {
    map.entries[map.count].quantity = q;
    map.entries[map.count].spec = spec(t);
    map.entries[map.count].spec.address = a;
    map.entries[map.count].spec.function = f;
    ++map.count;
  };
  add(hal::ScadaQuantity::kWindSpeed, 100, RegisterType::kFloat32, hal::RegisterFunction::kHolding);
  add(hal::ScadaQuantity::kRotorSpeed, 102, RegisterType::kUInt16, hal::RegisterFunction::kHolding);
  add(hal::ScadaQuantity::kPower, 110, RegisterType::kUInt16, hal::RegisterFunction::kHolding);
  add(hal::ScadaQuantity::kPitch, 5, RegisterType::kUInt16, hal::RegisterFunction::kInput);
  std::array<hal::ReadBlock, hal::kMaxReadBlocks> blocks{};

  // Act
  const std::size_t n_tight = hal::plan_reads(map, 0, blocks);
  const auto first_tight = blocks[0];
  const std::size_t n_loose = hal::plan_reads(map, 8, blocks);

  // Assert: hole of 7 registers (103..109) splits with max_hole 0, merges with 8
  EXPECT_EQ(n_tight, 3u);
  EXPECT_EQ(first_tight.start, 100);
  EXPECT_EQ(first_tight.count, 3);
  ASSERT_EQ(n_loose, 2u);
  EXPECT_EQ(blocks[0].start, 100);
  EXPECT_EQ(blocks[0].count, 11);
  EXPECT_EQ(blocks[1].function, hal::RegisterFunction::kInput);
}

TEST(ModbusCodec, ValidateMapFindsOverlapsDuplicatesAndZeroScale) {
  // Arrange
  hal::ScadaRegisterMap map;
  map.count = 2;
  map.entries[0] = {hal::ScadaQuantity::kWindSpeed, spec(RegisterType::kFloat32)};
  map.entries[1] = {hal::ScadaQuantity::kRotorSpeed, spec(RegisterType::kUInt16)};
  map.entries[1].spec.address = 1;  // inside the float at 0..1

  // Act / Assert
  EXPECT_EQ(hal::validate_map(map), std::optional<std::size_t>(1));
  map.entries[1].spec.address = 2;
  EXPECT_FALSE(hal::validate_map(map));
  map.entries[1].spec.scale = 0.0;
  EXPECT_EQ(hal::validate_map(map), std::optional<std::size_t>(1));
  map.entries[1].spec.scale = 1.0;
  map.entries[1].quantity = hal::ScadaQuantity::kWindSpeed;
  EXPECT_EQ(hal::validate_map(map), std::optional<std::size_t>(1));
  map.entries[1].quantity = hal::ScadaQuantity::kRotorSpeed;
  map.entries[1].spec.address = 65535;
  map.entries[1].spec.type = RegisterType::kInt32;  // would need 65535..65536
  EXPECT_EQ(hal::validate_map(map), std::optional<std::size_t>(1));
}

TEST(RegisterImage, PutRegisterWritesTheWordsOfEachTypeAtItsAddress) {
  // Arrange
  hal::RegisterImage img;
  img.count = 12;
  // Act
  const bool u32 =
      hal::put_register(img, 4, RegisterType::kUInt32, WordOrder::kHighWordFirst, 0x00010002);
  const bool f32 = hal::put_register(img, 8, RegisterType::kFloat32, WordOrder::kHighWordFirst,
                                     361747.0);  // 0x48B0A260, by hand from IEEE 754
  const bool low = hal::put_register(img, 10, RegisterType::kFloat32, WordOrder::kLowWordFirst,
                                     -12.5);  // 0xC1480000
  const bool i16 = hal::put_register(img, 0, RegisterType::kInt16, WordOrder::kHighWordFirst, -2);
  // Assert
  EXPECT_TRUE(u32 && f32 && low && i16);
  EXPECT_EQ(img.words[4], 0x0001);
  EXPECT_EQ(img.words[5], 0x0002);
  EXPECT_EQ(img.words[8], 0x48B0);
  EXPECT_EQ(img.words[9], 0xA260);
  EXPECT_EQ(img.words[10], 0x0000);
  EXPECT_EQ(img.words[11], 0xC148);
  EXPECT_EQ(img.words[0], 0xFFFE);
}

TEST(RegisterImage, PutRegisterRefusesWhatDoesNotFitTheImageOrTheType) {
  hal::RegisterImage img;
  img.count = 10;
  EXPECT_FALSE(hal::put_register(img, 9, RegisterType::kUInt32, WordOrder::kHighWordFirst, 1));
  EXPECT_FALSE(hal::put_register(img, 0, RegisterType::kUInt16, WordOrder::kHighWordFirst, 70000));
  EXPECT_FALSE(hal::put_register(img, 0, RegisterType::kUInt16, WordOrder::kHighWordFirst, -1));
  EXPECT_EQ(img.words[9], 0);
  EXPECT_EQ(img.words[0], 0);
}

}  // namespace
