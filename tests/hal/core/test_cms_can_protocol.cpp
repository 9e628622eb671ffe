// The CMS frame protocol against frames whose bytes are written out by hand
// from the layout in hal/cms_can_protocol.hpp / hal/README.md.
#include <gtest/gtest.h>

#include "hal/cms_can_protocol.hpp"

namespace {

using hal::CanFrame;
using hal::CmsDecodeError;
using hal::CmsFrame;
using hal::CmsSampleFormat;

constexpr std::uint32_t kBase = 0x180;

CanFrame fd_frame(std::uint32_t id, std::initializer_list<std::uint8_t> bytes) {
  CanFrame f;
  f.id = id;
  f.fd = true;
  f.len = static_cast<std::uint8_t>(bytes.size());
  std::size_t i = 0;
  for (auto b : bytes) f.data[i++] = b;
  return f;
}

TEST(CmsCanProtocol, DecodesAnInt16FdFrameWrittenOutByHand) {
  // Arrange: channel 2, version 1 → byte0 0x12; int16, 2 samples → byte1 0x02;
  // sequence 0x0304 → 04 03; t0 = 0x01020304 µs → 04 03 02 01;
  // samples 1000 (0x03E8 → E8 03) and -2 (0xFFFE → FE FF); 12 bytes used: length 12.
  const CanFrame f =
      fd_frame(kBase + 2, {0x12, 0x02, 0x04, 0x03, 0x04, 0x03, 0x02, 0x01, 0xE8, 0x03, 0xFE, 0xFF});
  CmsFrame out;

  // Act
  const CmsDecodeError e = hal::decode_cms_frame(f, kBase, CmsSampleFormat::kInt16, out);

  // Assert
  ASSERT_EQ(e, CmsDecodeError::kNone) << hal::to_string(e);
  EXPECT_EQ(out.channel, 2);
  EXPECT_EQ(out.sequence, 0x0304);
  ASSERT_TRUE(out.t0_us);
  EXPECT_EQ(*out.t0_us, 0x01020304u);
  ASSERT_EQ(out.count, 2);
  EXPECT_EQ(out.raw[0], 1000);
  EXPECT_EQ(out.raw[1], -2);
}

TEST(CmsCanProtocol, DecodesInt24SamplesWithSignExtensionAndPaddingToTheFdLength) {
  // Arrange: channel 0, int24 (0b01 << 6) with 2 samples → byte1 0x42; 8 + 6 = 14 bytes → DLC
  // length 16. samples 0x7FFFFF (max) and -8388608 (0x800000).
  const CanFrame f = fd_frame(
      kBase, {0x10, 0x42, 0x00, 0x00, 0, 0, 0, 0, 0xFF, 0xFF, 0x7F, 0x00, 0x00, 0x80, 0, 0});
  CmsFrame out;

  // Act
  const CmsDecodeError e = hal::decode_cms_frame(f, kBase, CmsSampleFormat::kInt16, out);

  // Assert
  ASSERT_EQ(e, CmsDecodeError::kNone) << hal::to_string(e);
  EXPECT_EQ(out.format, CmsSampleFormat::kInt24);
  EXPECT_EQ(out.raw[0], 8388607);
  EXPECT_EQ(out.raw[1], -8388608);
}

TEST(CmsCanProtocol, DecodesAClassicFrameWithTheConfiguredFormat) {
  // Arrange: sequence 7, samples 1, -1, 256
  CanFrame f;
  f.id = kBase + 5;
  f.len = 8;
  const std::uint8_t b[8] = {0x07, 0x00, 0x01, 0x00, 0xFF, 0xFF, 0x00, 0x01};
  for (int i = 0; i < 8; ++i) f.data[static_cast<std::size_t>(i)] = b[i];
  CmsFrame out;

  // Act
  const CmsDecodeError e = hal::decode_cms_frame(f, kBase, CmsSampleFormat::kInt16, out);

  // Assert
  ASSERT_EQ(e, CmsDecodeError::kNone);
  EXPECT_EQ(out.channel, 5);
  EXPECT_EQ(out.sequence, 7);
  EXPECT_FALSE(out.t0_us);
  ASSERT_EQ(out.count, 3);
  EXPECT_EQ(out.raw[0], 1);
  EXPECT_EQ(out.raw[1], -1);
  EXPECT_EQ(out.raw[2], 256);
}

TEST(CmsCanProtocol, RejectsEachKindOfMalformedFrame) {
  // Arrange / Act / Assert, one malformation at a time from a good 12-byte frame.
  const CanFrame good = fd_frame(kBase + 2, {0x12, 0x02, 0, 0, 0, 0, 0, 0, 1, 0, 2, 0});
  CmsFrame out;
  ASSERT_EQ(hal::decode_cms_frame(good, kBase, CmsSampleFormat::kInt16, out),
            CmsDecodeError::kNone);

  CanFrame f = good;
  f.id = kBase + 16;
  EXPECT_EQ(hal::decode_cms_frame(f, kBase, CmsSampleFormat::kInt16, out),
            CmsDecodeError::kNotCmsId);
  f = good;
  f.extended = true;
  EXPECT_EQ(hal::decode_cms_frame(f, kBase, CmsSampleFormat::kInt16, out),
            CmsDecodeError::kNotCmsId);
  f = good;
  f.data[0] = 0x22;  // version 2
  EXPECT_EQ(hal::decode_cms_frame(f, kBase, CmsSampleFormat::kInt16, out),
            CmsDecodeError::kBadVersion);
  f = good;
  f.data[0] = 0x13;  // channel 3 on the id of channel 2
  EXPECT_EQ(hal::decode_cms_frame(f, kBase, CmsSampleFormat::kInt16, out),
            CmsDecodeError::kChannelMismatch);
  f = good;
  f.data[1] = 0x82;  // format 2 (reserved)
  EXPECT_EQ(hal::decode_cms_frame(f, kBase, CmsSampleFormat::kInt16, out),
            CmsDecodeError::kBadFormat);
  f = good;
  f.data[1] = 0x00;  // zero samples
  EXPECT_EQ(hal::decode_cms_frame(f, kBase, CmsSampleFormat::kInt16, out),
            CmsDecodeError::kBadCount);
  f = good;
  f.data[1] = 0x1D;  // 29 int16 samples cannot fit 64 bytes
  EXPECT_EQ(hal::decode_cms_frame(f, kBase, CmsSampleFormat::kInt16, out),
            CmsDecodeError::kBadCount);
  f = good;
  f.data[1] = 0x03;  // says 3 samples (14 bytes) but the frame has 12
  EXPECT_EQ(hal::decode_cms_frame(f, kBase, CmsSampleFormat::kInt16, out),
            CmsDecodeError::kBadLength);
  f = good;
  f.len = 16;  // 12 bytes used must travel as length 12, not 16
  EXPECT_EQ(hal::decode_cms_frame(f, kBase, CmsSampleFormat::kInt16, out),
            CmsDecodeError::kBadLength);
  f = fd_frame(kBase, {0x10, 0x42, 0, 0, 0, 0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 9});  // padding byte 9
  EXPECT_EQ(hal::decode_cms_frame(f, kBase, CmsSampleFormat::kInt16, out),
            CmsDecodeError::kNonZeroPadding);
  f = good;
  f.fd = false;  // classic frames are exactly 8 bytes
  EXPECT_EQ(hal::decode_cms_frame(f, kBase, CmsSampleFormat::kInt16, out),
            CmsDecodeError::kBadLength);
  f = good;
  f.error = true;
  EXPECT_EQ(hal::decode_cms_frame(f, kBase, CmsSampleFormat::kInt16, out),
            CmsDecodeError::kErrorFrame);
}

TEST(CmsCanProtocol, EncodeThenDecodeReturnsTheBlockForEveryCountAndFormat) {
  for (auto fmt : {CmsSampleFormat::kInt16, CmsSampleFormat::kInt24}) {
    for (std::size_t n = 1; n <= hal::max_fd_samples(fmt); ++n) {
      // Arrange
      CmsFrame in;
      in.channel = 9;
      in.format = fmt;
      in.sequence = static_cast<std::uint16_t>(60000 + n);
      in.t0_us = 4000000000u;
      in.count = static_cast<std::uint8_t>(n);
      for (std::size_t i = 0; i < n; ++i) in.raw[i] = static_cast<std::int32_t>(i * 997) - 12000;
      CanFrame f;
      CmsFrame out;

      // Act
      ASSERT_TRUE(hal::encode_cms_fd_frame(in, kBase, f));
      const auto e = hal::decode_cms_frame(f, kBase, CmsSampleFormat::kInt16, out);

      // Assert
      ASSERT_EQ(e, CmsDecodeError::kNone) << n;
      EXPECT_EQ(f.len, hal::can_fd_length(8 + n * hal::bytes_per_sample(fmt)));
      EXPECT_EQ(out.sequence, in.sequence);
      EXPECT_EQ(*out.t0_us, *in.t0_us);
      for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(out.raw[i], in.raw[i]);
    }
  }
}

TEST(CmsCanProtocol, EncoderRefusesSamplesOutsideTheFormatRange) {
  // Arrange
  CmsFrame in;
  in.count = 1;
  in.raw[0] = 40000;  // > int16 max
  CanFrame f;

  // Act / Assert
  EXPECT_FALSE(hal::encode_cms_fd_frame(in, kBase, f));
  in.format = CmsSampleFormat::kInt24;
  EXPECT_TRUE(hal::encode_cms_fd_frame(in, kBase, f));
}

TEST(SequenceTracker, ClassifiesInOrderGapDuplicateAndLateFramesAcrossTheWrap) {
  // Arrange
  hal::SequenceTracker t;
  using V = hal::SequenceTracker::Verdict;

  // Act / Assert
  EXPECT_EQ(t.on_sequence(65534).verdict, V::kFirst);
  EXPECT_EQ(t.on_sequence(65535).verdict, V::kInOrder);
  EXPECT_EQ(t.on_sequence(0).verdict, V::kInOrder);  // wrap
  EXPECT_EQ(t.on_sequence(0).verdict, V::kDuplicate);
  const auto gap = t.on_sequence(4);  // 1, 2, 3 lost
  EXPECT_EQ(gap.verdict, V::kGap);
  EXPECT_EQ(gap.lost, 3);
  EXPECT_EQ(t.on_sequence(2).verdict, V::kReordered);      // late
  EXPECT_EQ(t.on_sequence(65535).verdict, V::kReordered);  // from before the wrap
  EXPECT_EQ(t.on_sequence(5).verdict, V::kInOrder);        // late frames did not move the reference
}

TEST(TimestampUnwrapper, ContinuesAcrossThe32BitMicrosecondWrap) {
  // Arrange: 2^32 µs = 4294.967296 s
  hal::TimestampUnwrapper u;

  // Act
  const auto a = u.unwrap(0xFFFFFF00u);
  const auto b = u.unwrap(0x00000100u);     // 0x200 µs later, after the wrap
  const auto late = u.unwrap(0xFFFFFF80u);  // a late frame from before the wrap
  const auto c = u.unwrap(0x00000200u);

  // Assert
  EXPECT_EQ((b - a).count(), 0x200 * 1000);
  EXPECT_EQ((late - a).count(), 0x80 * 1000);
  EXPECT_EQ((c - b).count(), 0x100 * 1000);
}

TEST(CanErrorFrames, AreClassifiedFromTheLinuxErrorClassBits) {
  // Arrange: controller problem with RX passive (data[1] = 0x10), and a bus-off frame
  std::array<std::uint8_t, 64> data{};
  data[1] = 0x10;

  // Act
  const auto passive = hal::classify_error_frame(0x004, data);
  const auto off = hal::classify_error_frame(0x040, {});
  const auto restarted = hal::classify_error_frame(0x100, {});

  // Assert
  EXPECT_TRUE(passive.error_passive);
  EXPECT_FALSE(passive.bus_off);
  EXPECT_TRUE(off.bus_off);
  EXPECT_TRUE(restarted.restarted);
}

}  // namespace
