// SocketCAN CMS stream: see hal/socketcan_cms_stream.hpp.
#include "hal/socketcan_cms_stream.hpp"

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <boost/lockfree/spsc_queue.hpp>
#include <cerrno>
#include <cstring>
#include <thread>

namespace hal {

// The protocol header mirrors the kernel's error classes without including it.
static_assert(kCanErrTxTimeout == CAN_ERR_TX_TIMEOUT && kCanErrLostArb == CAN_ERR_LOSTARB &&
              kCanErrCrtl == CAN_ERR_CRTL && kCanErrProt == CAN_ERR_PROT && kCanErrTrx == CAN_ERR_TRX &&
              kCanErrAck == CAN_ERR_ACK && kCanErrBusOff == CAN_ERR_BUSOFF && kCanErrBusError == CAN_ERR_BUSERROR &&
              kCanErrRestarted == CAN_ERR_RESTARTED);
static_assert(kCanErrCrtlRxWarning == CAN_ERR_CRTL_RX_WARNING && kCanErrCrtlTxWarning == CAN_ERR_CRTL_TX_WARNING &&
              kCanErrCrtlRxPassive == CAN_ERR_CRTL_RX_PASSIVE && kCanErrCrtlTxPassive == CAN_ERR_CRTL_TX_PASSIVE);

namespace {
constexpr std::chrono::milliseconds kPollTick{100};
constexpr int kMaxFramesPerWake = 256;  // bounded burst before re-checking stop
}  // namespace

struct SocketCanCmsStream::Impl {
  Impl(const SocketCanConfig& c, const Clock& clk) : config(c), clock(clk) {}

  SocketCanConfig config;
  const Clock& clock;
  std::atomic<LifecycleState> lifecycle{LifecycleState::kUnconfigured};
  std::atomic<int> sock{-1};
  int wake_fd = -1;
  std::thread thread;
  std::atomic<bool> stop{false};
  std::atomic<bool> active{false};

  boost::lockfree::spsc_queue<CmsBlock, boost::lockfree::capacity<kSocketCanQueueBlocks>> queue;
  std::array<SequenceTracker, kCmsMaxChannels> trackers{};
  std::array<TimestampUnwrapper, kCmsMaxChannels> unwrappers{};

  std::atomic<std::uint64_t> blocks{0}, gaps{0}, lost{0}, duplicates{0}, reordered{0}, malformed{0},
      error_frames{0}, bus_off_events{0}, recoveries{0}, overflows{0};
  std::atomic<bool> bus_off{false};
  std::atomic<bool> link_down{false};
  std::atomic<std::int64_t> last_frame_ns{0};
  std::atomic<std::int64_t> last_error_ns{INT64_MIN / 2};

  int open_socket() {
    const int s = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
    if (s < 0) return -1;
    if (config.fd) {
      const int on = 1;
      if (::setsockopt(s, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof on) != 0) {
        ::close(s);
        return -1;
      }
    }
    const can_err_mask_t err_mask = CAN_ERR_MASK;
    ::setsockopt(s, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof err_mask);
    // Only the 16 CMS ids reach user space (error frames pass the error filter).
    std::array<can_filter, kCmsMaxChannels> filters{};
    for (std::size_t i = 0; i < filters.size(); ++i) {
      filters[i].can_id = config.base_id + static_cast<canid_t>(i);
      filters[i].can_mask = CAN_EFF_FLAG | CAN_RTR_FLAG | CAN_SFF_MASK;
    }
    ::setsockopt(s, SOL_CAN_RAW, CAN_RAW_FILTER, filters.data(), static_cast<socklen_t>(sizeof filters));
    ifreq ifr{};
    std::strncpy(ifr.ifr_name, config.interface.c_str(), IFNAMSIZ - 1);
    if (::ioctl(s, SIOCGIFINDEX, &ifr) != 0) {
      ::close(s);
      return -1;
    }
    sockaddr_can addr{};
    addr.can_family = AF_CAN;
    addr.can_ifindex = ifr.ifr_ifindex;
    if (::bind(s, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
      ::close(s);
      return -1;
    }
    return s;
  }

  void on_error_frame(const canfd_frame& f, Timestamp now) {
    ++error_frames;
    last_error_ns = now.count();
    CanFrame cf;
    cf.error = true;
    std::memcpy(cf.data.data(), f.data, std::min<std::size_t>(f.len, CAN_MAX_DLEN));
    const CanErrorInfo info = classify_error_frame(f.can_id & CAN_ERR_MASK, cf.data);
    if (info.bus_off && !bus_off.exchange(true)) ++bus_off_events;
    if (info.restarted && bus_off.exchange(false)) ++recoveries;
  }

  void on_data_frame(const canfd_frame& f, bool is_fd, Timestamp now) {
    CanFrame cf;
    cf.id = f.can_id & (f.can_id & CAN_EFF_FLAG ? CAN_EFF_MASK : CAN_SFF_MASK);
    cf.extended = (f.can_id & CAN_EFF_FLAG) != 0;
    cf.fd = is_fd;
    cf.len = std::min<std::uint8_t>(f.len, CANFD_MAX_DLEN);
    std::memcpy(cf.data.data(), f.data, cf.len);
    cf.stamp = now;
    CmsFrame frame;
    if (decode_cms_frame(cf, config.base_id, config.classic_format, frame) != CmsDecodeError::kNone ||
        config.scale[frame.channel] == 0.0f) {
      ++malformed;
      return;
    }
    last_frame_ns = now.count();
    if (bus_off.exchange(false)) ++recoveries;  // a good frame: the bus is back
    const auto verdict = trackers[frame.channel].on_sequence(frame.sequence);
    using V = SequenceTracker::Verdict;
    if (verdict.verdict == V::kDuplicate) {
      ++duplicates;
      return;
    }
    if (verdict.verdict == V::kReordered) {
      ++reordered;
      return;
    }
    if (verdict.verdict == V::kGap) {
      ++gaps;
      lost += verdict.lost;
    }
    CmsBlock b;
    b.channel = frame.channel;
    b.sequence = frame.sequence;
    b.count = frame.count;
    b.received = now;
    b.stamp = frame.t0_us ? unwrappers[frame.channel].unwrap(*frame.t0_us) : now;
    const float scale = config.scale[frame.channel];
    for (std::size_t i = 0; i < frame.count; ++i) b.samples[i] = static_cast<float>(frame.raw[i]) * scale;
    if (!active.load()) return;
    if (!queue.push(b)) {
      ++overflows;
      return;
    }
    ++blocks;
  }

  /// Reads what is waiting. @return false if the socket failed (must re-open).
  bool drain(int s) {
    for (int i = 0; i < kMaxFramesPerWake; ++i) {
      canfd_frame f{};
      const ssize_t n = ::read(s, &f, sizeof f);
      if (n < 0) return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR;
      const Timestamp now = clock.now();
      if (n != CAN_MTU && n != CANFD_MTU) {
        ++malformed;
        continue;
      }
      if (f.can_id & CAN_ERR_FLAG) {
        on_error_frame(f, now);
        continue;
      }
      if (f.can_id & CAN_RTR_FLAG) {
        ++malformed;
        continue;
      }
      on_data_frame(f, n == CANFD_MTU, now);
    }
    return true;
  }

  void run() {
    std::chrono::milliseconds backoff = config.min_backoff;
    auto next_open = std::chrono::steady_clock::now();
    while (!stop.load()) {
      int s = sock.load();
      if (s < 0) {
        if (std::chrono::steady_clock::now() >= next_open) {
          s = open_socket();
          if (s >= 0) {
            sock = s;
            link_down = false;
            ++recoveries;
            backoff = config.min_backoff;
          } else {
            next_open = std::chrono::steady_clock::now() + backoff;
            backoff = std::min(backoff * 2, config.max_backoff);
          }
        }
      }
      std::array<pollfd, 2> fds{{{wake_fd, POLLIN, 0}, {s, POLLIN, 0}}};
      const int nfds = s >= 0 ? 2 : 1;
      const int ready = ::poll(fds.data(), static_cast<nfds_t>(nfds), static_cast<int>(kPollTick.count()));
      if (ready < 0) continue;
      if (fds[0].revents & POLLIN) {
        std::uint64_t v;
        [[maybe_unused]] const ssize_t r = ::read(wake_fd, &v, sizeof v);
      }
      if (s >= 0 && (fds[1].revents & (POLLIN | POLLERR | POLLHUP))) {
        if (!drain(s) || (fds[1].revents & (POLLERR | POLLHUP))) {
          // Interface gone or down (ENETDOWN, ENODEV): close and re-open with back-off.
          ::close(s);
          sock = -1;
          link_down = true;
          next_open = std::chrono::steady_clock::now() + backoff;
        }
      }
    }
  }

  void wake() {
    const std::uint64_t one = 1;
    [[maybe_unused]] const ssize_t r = ::write(wake_fd, &one, sizeof one);
  }
};

SocketCanCmsStream::SocketCanCmsStream(const SocketCanConfig& config, const Clock& clock)
    : impl_(std::make_unique<Impl>(config, clock)) {}

SocketCanCmsStream::~SocketCanCmsStream() {
  Impl& m = *impl_;
  if (m.thread.joinable()) {
    m.stop = true;
    m.wake();
    m.thread.join();
  }
  if (m.sock >= 0) ::close(m.sock);
  if (m.wake_fd >= 0) ::close(m.wake_fd);
}

Status SocketCanCmsStream::configure() {
  Impl& m = *impl_;
  if (m.lifecycle != LifecycleState::kUnconfigured) return Status::kWrongState;
  if (m.config.interface.empty() || m.config.interface.size() >= IFNAMSIZ || m.config.base_id + 15 > CAN_SFF_MASK ||
      m.config.min_backoff <= std::chrono::milliseconds(0) || m.config.max_backoff < m.config.min_backoff)
    return Status::kInvalidConfig;
  bool any = false;
  for (float s : m.config.scale) any |= s != 0.0f;
  if (!any) return Status::kInvalidConfig;
  const int s = m.open_socket();
  if (s < 0) return Status::kIoError;
  m.sock = s;
  m.wake_fd = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (m.wake_fd < 0) return Status::kIoError;
  m.last_frame_ns = m.clock.now().count();
  m.thread = std::thread([&m] { m.run(); });
  m.lifecycle = LifecycleState::kInactive;
  return Status::kOk;
}

Status SocketCanCmsStream::activate() {
  Impl& m = *impl_;
  if (m.lifecycle == LifecycleState::kUnconfigured) return Status::kWrongState;
  m.active = true;
  m.lifecycle = LifecycleState::kActive;
  return Status::kOk;
}

Status SocketCanCmsStream::deactivate() {
  Impl& m = *impl_;
  if (m.lifecycle == LifecycleState::kUnconfigured) return Status::kOk;
  m.active = false;
  m.lifecycle = LifecycleState::kInactive;
  return Status::kOk;
}

LifecycleState SocketCanCmsStream::state() const { return impl_->lifecycle; }

Status SocketCanCmsStream::read(CmsBlock& out) {
  Impl& m = *impl_;
  if (m.lifecycle != LifecycleState::kActive) return Status::kWrongState;
  if (m.queue.pop(out)) return Status::kOk;
  if (m.bus_off) return Status::kBusOff;
  return Status::kNoData;
}

CmsStreamStats SocketCanCmsStream::stats() const {
  const Impl& m = *impl_;
  CmsStreamStats s;
  s.blocks = m.blocks;
  s.gaps = m.gaps;
  s.lost_blocks = m.lost;
  s.duplicates = m.duplicates;
  s.reordered = m.reordered;
  s.malformed = m.malformed;
  s.error_frames = m.error_frames;
  s.bus_off = m.bus_off_events;
  s.recoveries = m.recoveries;
  s.overflows = m.overflows;
  return s;
}

Status SocketCanCmsStream::health(Timestamp now) const {
  const Impl& m = *impl_;
  if (m.bus_off) return Status::kBusOff;
  if (m.link_down) return Status::kDisconnected;
  if (now - Timestamp{m.last_error_ns.load()} < m.config.error_hold) return Status::kBusError;
  if (now - Timestamp{m.last_frame_ns.load()} > m.config.stale_after) return Status::kStale;
  return Status::kOk;
}

Status SocketCanCmsStream::send_heartbeat(std::uint16_t counter, std::uint16_t status_word) {
  Impl& m = *impl_;
  const int s = m.sock.load();
  if (s < 0) return Status::kDisconnected;
  can_frame f{};
  f.can_id = m.config.heartbeat_id & CAN_SFF_MASK;
  f.can_dlc = 4;
  f.data[0] = static_cast<std::uint8_t>(counter & 0xFF);
  f.data[1] = static_cast<std::uint8_t>(counter >> 8);
  f.data[2] = static_cast<std::uint8_t>(status_word & 0xFF);
  f.data[3] = static_cast<std::uint8_t>(status_word >> 8);
  const ssize_t n = ::write(s, &f, sizeof f);
  if (n == static_cast<ssize_t>(sizeof f)) return Status::kOk;
  if (n < 0 && (errno == EAGAIN || errno == ENOBUFS)) return Status::kOverflow;
  return Status::kIoError;
}

}  // namespace hal
