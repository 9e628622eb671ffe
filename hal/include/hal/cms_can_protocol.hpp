#pragma once
// The CMS frame protocol over CAN FD (and classic CAN at a reduced rate):
// how the condition-monitoring front end puts accelerometer samples on the bus.
// Documented for integrators in hal/README.md ("CMS over CAN"); summary:
//
//   CAN id (11-bit)  = base_id + channel            channel 0..15, base_id configured (default
//   0x180) CAN FD payload (up to 64 bytes, header 8 bytes, little-endian):
//     byte 0   bits 7..4 protocol version (1)   bits 3..0 channel (must equal id - base_id)
//     byte 1   bits 7..6 sample format (0 = int16, 1 = int24)   bits 5..0 sample count n >= 1
//     byte 2-3 sequence number, uint16, per channel, +1 per frame, wraps
//     byte 4-7 t0: time of sample 0 [µs] of the front end's free-running clock, uint32, wraps
//     byte 8.. n samples, two's complement, packed (2 or 3 bytes each), then zero padding
//              to the CAN FD length; value = raw × scale (scale [unit/LSB] configured per channel)
//     n ≤ 28 (int16) or 18 (int24) so that a frame fits 64 bytes.
//   Classic CAN payload (8 bytes, DLC 8): no room for a header beyond the sequence:
//     byte 0-1 sequence number, uint16;  byte 2-7: 3 int16 or 2 int24 samples (format configured);
//     the block time stamp is the frame's receive time (accuracy: bus latency).
//
// Sequence tracking per channel (SequenceTracker): distance d = seq − last (mod 2^16):
// d = 0 duplicate (dropped), 1 ≤ d < 2^15 in order (d − 1 blocks lost: a gap),
// d ≥ 2^15 an old frame arriving late (reordered, dropped).
//
// Error frames (Linux SocketCAN semantics, linux/can/error.h): classified by
// classify_error_frame(); bus-off is reported until a "restarted" error frame
// or a good data frame arrives.
//
// Thread context: everything here is pure or a plain value type: no I/O, no
// allocation; safe on the RT thread and in fuzzers.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "hal/clock.hpp"
#include "hal/cms_stream.hpp"

namespace hal {

/// A CAN or CAN FD frame as the hal sees it (no <linux/can.h> in hal's headers).
struct CanFrame {
  std::uint32_t id = 0;   // 11- or 29-bit identifier (flags stripped)
  bool extended = false;  // 29-bit identifier
  bool fd = false;        // CAN FD frame
  bool error = false;     // error frame (id holds the error class bits)
  std::uint8_t len = 0;   // [bytes] payload length 0..64
  std::array<std::uint8_t, 64> data{};
  Timestamp stamp{0};  // [ns] receive time (kernel time stamp when available)
};

inline constexpr std::uint8_t kCmsProtocolVersion = 1;
inline constexpr std::size_t kCmsFdHeaderBytes = 8;

enum class CmsSampleFormat : std::uint8_t { kInt16 = 0, kInt24 = 1 };

constexpr std::size_t bytes_per_sample(CmsSampleFormat f) {
  return f == CmsSampleFormat::kInt16 ? 2 : 3;
}
/// Most samples in a CAN FD frame of 64 bytes.
constexpr std::size_t max_fd_samples(CmsSampleFormat f) {
  return (64 - kCmsFdHeaderBytes) / bytes_per_sample(f);
}
/// Samples in a classic 8-byte frame.
constexpr std::size_t classic_samples(CmsSampleFormat f) { return 6 / bytes_per_sample(f); }
/// Smallest valid CAN FD data length >= n (0..8, 12, 16, 20, 24, 32, 48, 64).
constexpr std::uint8_t can_fd_length(std::size_t n) {
  if (n <= 8) return static_cast<std::uint8_t>(n);
  constexpr std::uint8_t kLens[] = {12, 16, 20, 24, 32, 48, 64};
  for (auto l : kLens)
    if (n <= l) return l;
  return 0;  // does not fit
}

/// One decoded frame, before sequence tracking.
struct CmsFrame {
  std::uint8_t channel = 0;
  CmsSampleFormat format = CmsSampleFormat::kInt16;
  std::uint16_t sequence = 0;
  std::optional<std::uint32_t> t0_us;  // FD: front-end time of sample 0 [µs]; classic: none
  std::uint8_t count = 0;
  std::array<std::int32_t, kCmsMaxSamplesPerBlock> raw{};  // [LSB]
};

enum class CmsDecodeError : std::uint8_t {
  kNone = 0,
  kNotCmsId,         // id outside base_id .. base_id+15, or extended id
  kErrorFrame,       // an error frame: use classify_error_frame
  kBadLength,        // payload too short / longer than the samples plus padding allow
  kBadVersion,       // unknown protocol version
  kChannelMismatch,  // byte-0 channel differs from the CAN id
  kBadFormat,        // reserved sample format
  kBadCount,         // zero samples or more than fit
  kNonZeroPadding,   // bytes after the samples are not zero (garbage)
};
const char* to_string(CmsDecodeError e);

/// Decodes one frame. Pure function of (frame bytes, base id, classic format).
/// @param frame           the frame as received
/// @param base_id         CAN id of channel 0
/// @param classic_format  sample format of classic (non-FD) frames
/// @param out             filled when the result is kNone
[[nodiscard]] CmsDecodeError decode_cms_frame(const CanFrame& frame, std::uint32_t base_id,
                                              CmsSampleFormat classic_format, CmsFrame& out);

/// Encodes a CMS block as a CAN FD frame (the front end's side; used by the
/// simulation backend, the rig tests and the fuzz corpus).
/// @return false if the block does not fit (count 0 or too many, raw out of range).
[[nodiscard]] bool encode_cms_fd_frame(const CmsFrame& block, std::uint32_t base_id, CanFrame& out);
/// Encodes a classic 8-byte frame (count must equal classic_samples(format)).
[[nodiscard]] bool encode_cms_classic_frame(const CmsFrame& block, std::uint32_t base_id,
                                            CanFrame& out);

/// Per-channel sequence bookkeeping.
class SequenceTracker {
 public:
  enum class Verdict : std::uint8_t { kFirst, kInOrder, kGap, kDuplicate, kReordered };
  struct Result {
    Verdict verdict = Verdict::kFirst;
    std::uint16_t lost = 0;  // blocks missing (kGap)
  };
  /// Classifies `sequence` against the last accepted one and accepts it unless
  /// it is a duplicate or reordered.
  Result on_sequence(std::uint16_t sequence);
  void reset() { have_last_ = false; }

 private:
  std::uint16_t last_ = 0;
  bool have_last_ = false;
};

/// Unwraps the front end's 32-bit µs counter into a 64-bit ns time line.
class TimestampUnwrapper {
 public:
  Timestamp unwrap(std::uint32_t t_us);
  void reset() { have_last_ = false; }

 private:
  std::uint32_t last_ = 0;
  std::int64_t high_ = 0;  // multiples of 2^32 µs
  bool have_last_ = false;
};

/// What an error frame says (Linux SocketCAN error classes).
struct CanErrorInfo {
  bool bus_off = false;
  bool restarted = false;  // controller restarted after bus-off
  bool error_passive = false;
  bool warning = false;
  bool protocol_error = false;
  bool tx_timeout = false;
  bool lost_arbitration = false;
  bool no_ack = false;
  bool bus_error = false;
};
/// @param error_class  the error frame's id bits (CAN_ERR_* class mask)
/// @param data         its 8 data bytes
CanErrorInfo classify_error_frame(std::uint32_t error_class,
                                  const std::array<std::uint8_t, 64>& data);

// Linux error-class bits (values of linux/can/error.h; checked against the
// kernel header in the SocketCAN backend).
inline constexpr std::uint32_t kCanErrTxTimeout = 0x001;
inline constexpr std::uint32_t kCanErrLostArb = 0x002;
inline constexpr std::uint32_t kCanErrCrtl = 0x004;
inline constexpr std::uint32_t kCanErrProt = 0x008;
inline constexpr std::uint32_t kCanErrTrx = 0x010;
inline constexpr std::uint32_t kCanErrAck = 0x020;
inline constexpr std::uint32_t kCanErrBusOff = 0x040;
inline constexpr std::uint32_t kCanErrBusError = 0x080;
inline constexpr std::uint32_t kCanErrRestarted = 0x100;
inline constexpr std::uint8_t kCanErrCrtlRxWarning = 0x04;
inline constexpr std::uint8_t kCanErrCrtlTxWarning = 0x08;
inline constexpr std::uint8_t kCanErrCrtlRxPassive = 0x10;
inline constexpr std::uint8_t kCanErrCrtlTxPassive = 0x20;

}  // namespace hal
