#pragma once
// CMS sample stream: blocks of accelerometer samples with a sequence number and
// the time stamp of their first sample, per channel, as they arrive from the
// condition-monitoring front end (SocketCAN), a replay or a simulation.
//
// Thread context: read() and stats() from the RT thread: pops from a bounded
// lock-free queue filled by the backend's I/O thread; never blocks, never
// allocates. When the queue is full the I/O thread drops the block and counts
// it (stats().overflows).

#include <array>
#include <cstddef>
#include <cstdint>

#include "hal/clock.hpp"
#include "hal/device.hpp"

namespace hal {

/// Most samples one block can hold: a CAN FD frame of 64 bytes minus the
/// 8-byte header, packed int16 (cms_can_protocol.hpp).
inline constexpr std::size_t kCmsMaxSamplesPerBlock = 28;
/// Most channels the stream can carry (channel id is 4 bits on the wire).
inline constexpr std::size_t kCmsMaxChannels = 16;

struct CmsBlock {
  std::uint8_t channel = 0;    // [-] 0..kCmsMaxChannels-1
  std::uint16_t sequence = 0;  // [-] per-channel block counter, wraps
  std::uint8_t count = 0;      // [-] samples used in `samples`
  Timestamp stamp{0};          // [ns] time of samples[0] (source clock)
  Timestamp received{0};       // [ns] when the block was received (local clock)
  std::array<float, kCmsMaxSamplesPerBlock> samples{};  // in the channel's unit (e.g. m/s²)
};

/// Counters since configure(); monotonically increasing.
struct CmsStreamStats {
  std::uint64_t blocks = 0;        // blocks delivered
  std::uint64_t gaps = 0;          // sequence gaps detected (events)
  std::uint64_t lost_blocks = 0;   // blocks missing in those gaps
  std::uint64_t duplicates = 0;    // same sequence again: dropped
  std::uint64_t reordered = 0;     // older sequence arriving late: dropped
  std::uint64_t malformed = 0;     // frames that failed to decode: dropped
  std::uint64_t error_frames = 0;  // CAN error frames
  std::uint64_t bus_off = 0;       // bus-off events
  std::uint64_t recoveries = 0;    // successful recoveries from bus-off / disconnect
  std::uint64_t overflows = 0;     // blocks dropped because the queue was full
};

class CmsStream : public Device {
 public:
  /// Pops the oldest undelivered block.
  /// @return kOk with `out` filled; kNoData if none is waiting; kBusOff while the
  ///         bus is off (recovery runs in the background); kWrongState if not active.
  virtual Status read(CmsBlock& out) = 0;
  /// Snapshot of the counters (wait-free).
  virtual CmsStreamStats stats() const = 0;
  /// Health of the link right now: kOk, kBusError (recent error frames),
  /// kBusOff, kDisconnected, kStale (nothing for longer than the stale limit at `now`).
  virtual Status health(Timestamp now) const = 0;
};

}  // namespace hal
