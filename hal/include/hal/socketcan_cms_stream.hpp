#pragma once
// CMS sample stream from a SocketCAN interface (raw socket, CAN FD or classic),
// frames decoded with the protocol of cms_can_protocol.hpp on an I/O thread of
// its own and handed to the RT side through a bounded lock-free queue.
//
// Faults and recovery (each is counted in stats() and shown by health()):
// - gaps, duplicates, late frames: sequence tracking per channel;
// - malformed frames: dropped, counted;
// - error frames: counted; bus-off reported until the controller restarts
//   (CAN_ERR_RESTARTED) or a good frame arrives. Restarting the controller is
//   the kernel's job: configure the interface with `ip link set canX type can
//   restart-ms 100` (the box's network setup does);
// - interface down / socket error: the socket is closed and re-opened with
//   back-off, without restarting the twin.
// Time stamps: block.stamp is the front end's µs clock (unwrapped to ns) for
// CAN FD frames, the receive time for classic frames; block.received is the
// receive time on the given Clock.
//
// Thread context: read/stats/health from the RT thread (wait-free);
// configure/activate/deactivate and send_heartbeat from the control thread.

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "hal/clock.hpp"
#include "hal/cms_can_protocol.hpp"
#include "hal/cms_stream.hpp"
#include "hal/thread.hpp"

namespace hal {

struct SocketCanConfig {
  std::string interface = "can0";
  bool fd = true;                 // accept CAN FD frames (needs an FD-capable interface)
  std::uint32_t base_id = 0x180;  // CAN id of channel 0
  CmsSampleFormat classic_format = CmsSampleFormat::kInt16;
  std::array<float, kCmsMaxChannels> scale{};   // [unit/LSB] per channel; 0 = channel not used
  std::chrono::milliseconds stale_after{1000};  // no frame this long → kStale
  std::chrono::milliseconds error_hold{
      1000};  // health kBusError for this long after an error frame
  std::chrono::milliseconds min_backoff{100};  // socket re-open back-off
  std::chrono::milliseconds max_backoff{5000};
  std::uint32_t heartbeat_id = 0x170;  // id of the twin's heartbeat frame (send_heartbeat)
  // The receive thread (app/ passes its thread table's entry).
  ThreadAttributes thread{"dt-cms", SchedPolicy::kOther, 0, -1, 0};
};

/// Blocks the queue between the I/O thread and the RT thread holds; when it is
/// full new blocks are dropped and counted (stats().overflows). 25.6 kHz × 4
/// channels / 28 samples per frame ≈ 3700 frames/s: this is ~0.5 s of data.
inline constexpr std::size_t kSocketCanQueueBlocks = 2048;

class SocketCanCmsStream final : public CmsStream {
 public:
  SocketCanCmsStream(const SocketCanConfig& config, const Clock& clock);
  ~SocketCanCmsStream() override;
  SocketCanCmsStream(const SocketCanCmsStream&) = delete;
  SocketCanCmsStream& operator=(const SocketCanCmsStream&) = delete;

  /// Opens and binds the raw socket (fails with kIoError if the interface does
  /// not exist), starts the I/O thread.
  Status configure() override;
  Status activate() override;
  Status deactivate() override;
  LifecycleState state() const override;
  Status read(CmsBlock& out) override;
  CmsStreamStats stats() const override;
  Status health(Timestamp now) const override;

  /// Sends the twin's heartbeat (classic frame, id heartbeat_id, 4 bytes:
  /// counter uint16 LE, status word uint16 LE). Non-blocking: kOverflow when
  /// the socket's transmit queue is full.
  Status send_heartbeat(std::uint16_t counter, std::uint16_t status_word);
  /// What the OS granted the I/O thread (valid after configure(); warning names refusals).
  const ThreadReport& thread_report() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hal
