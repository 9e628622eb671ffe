#pragma once
// From CAN frames to CMS blocks: the part of a CMS stream backend that does not
// depend on where frames come from (SocketCAN, the simulation backend, a
// fuzzer). Decodes with cms_can_protocol.hpp, tracks sequences per channel,
// unwraps front-end time stamps, classifies error frames, and keeps the
// counters and the link state behind CmsStream::stats() / health().
//
// Thread context: ingest() from one thread (the backend's I/O thread, or the
// caller's thread for the simulation); stats()/health() from any thread
// (atomics). No allocation, no blocking.

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>

#include "hal/cms_can_protocol.hpp"
#include "hal/cms_stream.hpp"
#include "hal/status.hpp"

namespace hal {

struct CmsIngestConfig {
  std::uint32_t base_id = 0x180;
  CmsSampleFormat classic_format = CmsSampleFormat::kInt16;
  std::array<float, kCmsMaxChannels>
      scale{};  // [unit/LSB]; 0 = channel not used (its frames are malformed)
  std::chrono::milliseconds stale_after{1000};  // health kStale when no good frame for this long
  std::chrono::milliseconds error_hold{1000};  // health reports an error/gap for this long after it
};

class CmsIngest {
 public:
  explicit CmsIngest(const CmsIngestConfig& config) : config_(config) {}

  /// Processes one frame received at `now`.
  /// @return kOk: `out` holds a new block; kGap: `out` holds a new block after
  ///         lost ones; kNoData: a duplicate or late frame, dropped;
  ///         kProtocolError: malformed, dropped; kBusError / kBusOff: an error frame.
  [[nodiscard]] Status ingest(const CanFrame& frame, Timestamp now, CmsBlock& out);

  /// Marks the start of reception (health is measured from here until a frame arrives).
  void start(Timestamp now) { last_frame_ns_ = now.count(); }
  void count_overflow() { ++overflows_; }
  void count_delivered() { ++blocks_; }
  void count_recovery() { ++recoveries_; }
  void set_link_down(bool down) { link_down_ = down; }

  CmsStreamStats stats() const;
  /// kBusOff, kDisconnected (link down), kBusError (error frame within error_hold),
  /// kProtocolError (malformed frame within error_hold), kGap (gap within error_hold),
  /// kStale (no good frame for stale_after), else kOk — in that order of precedence.
  Status health(Timestamp now) const;
  bool bus_off() const { return bus_off_.load(); }

 private:
  CmsIngestConfig config_;
  std::array<SequenceTracker, kCmsMaxChannels> trackers_{};
  std::array<TimestampUnwrapper, kCmsMaxChannels> unwrappers_{};
  std::atomic<std::uint64_t> blocks_{0}, gaps_{0}, lost_{0}, duplicates_{0}, reordered_{0},
      malformed_{0}, error_frames_{0}, bus_off_events_{0}, recoveries_{0}, overflows_{0};
  std::atomic<bool> bus_off_{false};
  std::atomic<bool> link_down_{false};
  std::atomic<std::int64_t> last_frame_ns_{0};
  std::atomic<std::int64_t> last_error_ns_{INT64_MIN / 2};
  std::atomic<std::int64_t> last_malformed_ns_{INT64_MIN / 2};
  std::atomic<std::int64_t> last_gap_ns_{INT64_MIN / 2};
};

}  // namespace hal
