// CMS frame protocol over CAN / CAN FD: see hal/cms_can_protocol.hpp and
// hal/README.md ("CMS over CAN").
#include "hal/cms_can_protocol.hpp"

namespace hal {
namespace {

constexpr std::uint32_t kChannelMask = 0x0F;

std::int32_t read_sample(const std::uint8_t* p, CmsSampleFormat f) {
  if (f == CmsSampleFormat::kInt16) {
    const auto u = static_cast<std::uint16_t>(p[0] | (p[1] << 8));
    return static_cast<std::int16_t>(u);
  }
  std::uint32_t u = static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
                    (static_cast<std::uint32_t>(p[2]) << 16);
  if (u & 0x800000u) u |= 0xFF000000u;  // sign-extend 24 → 32 bits
  return static_cast<std::int32_t>(u);
}

bool write_sample(std::int32_t v, CmsSampleFormat f, std::uint8_t* p) {
  const std::int32_t lo = f == CmsSampleFormat::kInt16 ? -32768 : -8388608;
  const std::int32_t hi = f == CmsSampleFormat::kInt16 ? 32767 : 8388607;
  if (v < lo || v > hi) return false;
  const auto u = static_cast<std::uint32_t>(v);
  p[0] = static_cast<std::uint8_t>(u & 0xFF);
  p[1] = static_cast<std::uint8_t>((u >> 8) & 0xFF);
  if (f == CmsSampleFormat::kInt24) p[2] = static_cast<std::uint8_t>((u >> 16) & 0xFF);
  return true;
}

}  // namespace

const char* to_string(CmsDecodeError e) {
  switch (e) {
    case CmsDecodeError::kNone:
      return "ok";
    case CmsDecodeError::kNotCmsId:
      return "CAN id is not a CMS channel";
    case CmsDecodeError::kErrorFrame:
      return "error frame";
    case CmsDecodeError::kBadLength:
      return "payload length does not match the header";
    case CmsDecodeError::kBadVersion:
      return "unknown protocol version";
    case CmsDecodeError::kChannelMismatch:
      return "channel in payload differs from CAN id";
    case CmsDecodeError::kBadFormat:
      return "reserved sample format";
    case CmsDecodeError::kBadCount:
      return "sample count out of range";
    case CmsDecodeError::kNonZeroPadding:
      return "non-zero padding after the samples";
  }
  return "unknown";
}

CmsDecodeError decode_cms_frame(const CanFrame& frame, std::uint32_t base_id,
                                CmsSampleFormat classic_format, CmsFrame& out) {
  if (frame.error) return CmsDecodeError::kErrorFrame;
  if (frame.extended || frame.id < base_id || frame.id > base_id + kChannelMask)
    return CmsDecodeError::kNotCmsId;
  const auto channel = static_cast<std::uint8_t>(frame.id - base_id);
  if (frame.len > frame.data.size()) return CmsDecodeError::kBadLength;

  if (!frame.fd) {
    if (frame.len != 8) return CmsDecodeError::kBadLength;
    if (classic_format != CmsSampleFormat::kInt16 && classic_format != CmsSampleFormat::kInt24)
      return CmsDecodeError::kBadFormat;
    out.channel = channel;
    out.format = classic_format;
    out.sequence = static_cast<std::uint16_t>(frame.data[0] | (frame.data[1] << 8));
    out.t0_us.reset();
    const std::size_t bps = bytes_per_sample(classic_format);
    out.count = static_cast<std::uint8_t>(classic_samples(classic_format));
    for (std::size_t i = 0; i < out.count; ++i)
      out.raw[i] = read_sample(&frame.data[2 + bps * i], classic_format);
    return CmsDecodeError::kNone;
  }

  if (frame.len < kCmsFdHeaderBytes) return CmsDecodeError::kBadLength;
  const std::uint8_t b0 = frame.data[0];
  const std::uint8_t b1 = frame.data[1];
  if ((b0 >> 4) != kCmsProtocolVersion) return CmsDecodeError::kBadVersion;
  if ((b0 & kChannelMask) != channel) return CmsDecodeError::kChannelMismatch;
  const auto fmt_code = static_cast<std::uint8_t>(b1 >> 6);
  if (fmt_code > 1) return CmsDecodeError::kBadFormat;
  const auto format = static_cast<CmsSampleFormat>(fmt_code);
  const std::size_t count = b1 & 0x3Fu;
  if (count == 0 || count > max_fd_samples(format)) return CmsDecodeError::kBadCount;
  const std::size_t used = kCmsFdHeaderBytes + count * bytes_per_sample(format);
  // The length must be the CAN FD length the sender had to round up to.
  if (frame.len < used || frame.len != can_fd_length(used)) return CmsDecodeError::kBadLength;
  for (std::size_t i = used; i < frame.len; ++i)
    if (frame.data[i] != 0) return CmsDecodeError::kNonZeroPadding;

  out.channel = channel;
  out.format = format;
  out.sequence = static_cast<std::uint16_t>(frame.data[2] | (frame.data[3] << 8));
  out.t0_us = static_cast<std::uint32_t>(frame.data[4]) |
              (static_cast<std::uint32_t>(frame.data[5]) << 8) |
              (static_cast<std::uint32_t>(frame.data[6]) << 16) |
              (static_cast<std::uint32_t>(frame.data[7]) << 24);
  out.count = static_cast<std::uint8_t>(count);
  const std::size_t bps = bytes_per_sample(format);
  for (std::size_t i = 0; i < count; ++i)
    out.raw[i] = read_sample(&frame.data[kCmsFdHeaderBytes + bps * i], format);
  return CmsDecodeError::kNone;
}

bool encode_cms_fd_frame(const CmsFrame& block, std::uint32_t base_id, CanFrame& out) {
  if (block.channel > kChannelMask || block.count == 0 ||
      block.count > max_fd_samples(block.format))
    return false;
  const std::size_t bps = bytes_per_sample(block.format);
  const std::size_t used = kCmsFdHeaderBytes + block.count * bps;
  out = CanFrame{};
  out.id = base_id + block.channel;
  out.fd = true;
  out.len = can_fd_length(used);
  out.data[0] = static_cast<std::uint8_t>((kCmsProtocolVersion << 4) | block.channel);
  out.data[1] =
      static_cast<std::uint8_t>((static_cast<std::uint8_t>(block.format) << 6) | block.count);
  out.data[2] = static_cast<std::uint8_t>(block.sequence & 0xFF);
  out.data[3] = static_cast<std::uint8_t>(block.sequence >> 8);
  const std::uint32_t t0 = block.t0_us.value_or(0);
  for (int i = 0; i < 4; ++i)
    out.data[4 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>((t0 >> (8 * i)) & 0xFF);
  for (std::size_t i = 0; i < block.count; ++i) {
    if (!write_sample(block.raw[i], block.format, &out.data[kCmsFdHeaderBytes + bps * i]))
      return false;
  }
  return true;
}

bool encode_cms_classic_frame(const CmsFrame& block, std::uint32_t base_id, CanFrame& out) {
  if (block.channel > kChannelMask || block.count != classic_samples(block.format)) return false;
  const std::size_t bps = bytes_per_sample(block.format);
  out = CanFrame{};
  out.id = base_id + block.channel;
  out.len = 8;
  out.data[0] = static_cast<std::uint8_t>(block.sequence & 0xFF);
  out.data[1] = static_cast<std::uint8_t>(block.sequence >> 8);
  for (std::size_t i = 0; i < block.count; ++i)
    if (!write_sample(block.raw[i], block.format, &out.data[2 + bps * i])) return false;
  return true;
}

SequenceTracker::Result SequenceTracker::on_sequence(std::uint16_t sequence) {
  if (!have_last_) {
    have_last_ = true;
    last_ = sequence;
    return {Verdict::kFirst, 0};
  }
  const auto d = static_cast<std::uint16_t>(sequence - last_);
  if (d == 0) return {Verdict::kDuplicate, 0};
  if (d >= 0x8000u) return {Verdict::kReordered, 0};
  last_ = sequence;
  if (d == 1) return {Verdict::kInOrder, 0};
  return {Verdict::kGap, static_cast<std::uint16_t>(d - 1)};
}

Timestamp TimestampUnwrapper::unwrap(std::uint32_t t_us) {
  if (have_last_) {
    // A step "backwards" by more than half the range is a wrap forwards.
    const auto d = static_cast<std::int32_t>(t_us - last_);
    if (d > 0 && t_us < last_) {
      ++high_;  // wrapped forwards
    } else if (d < 0 && t_us > last_) {
      --high_;  // a late frame from before the wrap
    }
  }
  have_last_ = true;
  last_ = t_us;
  const std::int64_t us = high_ * (std::int64_t{1} << 32) + static_cast<std::int64_t>(t_us);
  return std::chrono::microseconds(us);
}

CanErrorInfo classify_error_frame(std::uint32_t error_class,
                                  const std::array<std::uint8_t, 64>& data) {
  CanErrorInfo info;
  info.tx_timeout = (error_class & kCanErrTxTimeout) != 0;
  info.lost_arbitration = (error_class & kCanErrLostArb) != 0;
  info.protocol_error = (error_class & kCanErrProt) != 0;
  info.no_ack = (error_class & kCanErrAck) != 0;
  info.bus_off = (error_class & kCanErrBusOff) != 0;
  info.bus_error = (error_class & kCanErrBusError) != 0;
  info.restarted = (error_class & kCanErrRestarted) != 0;
  if (error_class & kCanErrCrtl) {
    const std::uint8_t ctrl = data[1];
    info.warning = (ctrl & (kCanErrCrtlRxWarning | kCanErrCrtlTxWarning)) != 0;
    info.error_passive = (ctrl & (kCanErrCrtlRxPassive | kCanErrCrtlTxPassive)) != 0;
  }
  return info;
}

}  // namespace hal
