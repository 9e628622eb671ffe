// SocketCAN CMS stream: see hal/socketcan_cms_stream.hpp.
#include "hal/socketcan_cms_stream.hpp"

#include "hal/cms_ingest.hpp"

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

namespace hal {

// The protocol header mirrors the kernel's error classes without including it.
static_assert(kCanErrTxTimeout == CAN_ERR_TX_TIMEOUT && kCanErrLostArb == CAN_ERR_LOSTARB &&
              kCanErrCrtl == CAN_ERR_CRTL && kCanErrProt == CAN_ERR_PROT &&
              kCanErrTrx == CAN_ERR_TRX && kCanErrAck == CAN_ERR_ACK &&
              kCanErrBusOff == CAN_ERR_BUSOFF && kCanErrBusError == CAN_ERR_BUSERROR &&
              kCanErrRestarted == CAN_ERR_RESTARTED);
static_assert(kCanErrCrtlRxWarning == CAN_ERR_CRTL_RX_WARNING &&
              kCanErrCrtlTxWarning == CAN_ERR_CRTL_TX_WARNING &&
              kCanErrCrtlRxPassive == CAN_ERR_CRTL_RX_PASSIVE &&
              kCanErrCrtlTxPassive == CAN_ERR_CRTL_TX_PASSIVE);

namespace {
constexpr std::chrono::milliseconds kPollTick{100};
constexpr int kMaxFramesPerWake = 256;  // bounded burst before re-checking stop
}  // namespace

struct SocketCanCmsStream::Impl {
  Impl(const SocketCanConfig& c, const Clock& clk)
      : config(c), clock(clk), ingest(ingest_config(c)) {}

  SocketCanConfig config;
  const Clock& clock;
  std::atomic<LifecycleState> lifecycle{LifecycleState::kUnconfigured};
  std::atomic<int> sock{-1};
  int wake_fd = -1;
  Thread thread;
  std::atomic<bool> stop{false};
  std::atomic<bool> active{false};

  boost::lockfree::spsc_queue<CmsBlock, boost::lockfree::capacity<kSocketCanQueueBlocks>> queue;
  CmsIngest ingest;

  static CmsIngestConfig ingest_config(const SocketCanConfig& c) {
    CmsIngestConfig i;
    i.base_id = c.base_id;
    i.classic_format = c.classic_format;
    i.scale = c.scale;
    i.stale_after = c.stale_after;
    i.error_hold = c.error_hold;
    return i;
  }

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
    ::setsockopt(s, SOL_CAN_RAW, CAN_RAW_FILTER, filters.data(),
                 static_cast<socklen_t>(sizeof filters));
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

  void on_frame(const canfd_frame& f, bool is_fd, Timestamp now) {
    CanFrame cf;
    cf.error = (f.can_id & CAN_ERR_FLAG) != 0;
    cf.extended = !cf.error && (f.can_id & CAN_EFF_FLAG) != 0;
    cf.id = f.can_id & (cf.error ? CAN_ERR_MASK : cf.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
    cf.fd = is_fd;
    cf.len = std::min<std::uint8_t>(f.len, CANFD_MAX_DLEN);
    std::memcpy(cf.data.data(), f.data, cf.len);
    cf.stamp = now;
    CmsBlock b;
    const Status s = ingest.ingest(cf, now, b);
    if ((s != Status::kOk && s != Status::kGap) || !active.load()) return;
    if (!queue.push(b)) {
      ingest.count_overflow();
      return;
    }
    ingest.count_delivered();
  }

  /// Reads what is waiting. @return false if the socket failed (must re-open).
  bool drain(int s) {
    for (int i = 0; i < kMaxFramesPerWake; ++i) {
      canfd_frame f{};
      const ssize_t n = ::read(s, &f, sizeof f);
      if (n < 0) return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR;
      const Timestamp now = clock.now();
      if (n != CAN_MTU && n != CANFD_MTU) continue;  // cannot happen on a raw CAN socket
      if ((f.can_id & CAN_RTR_FLAG) && !(f.can_id & CAN_ERR_FLAG))
        f.len = 0;  // remote frame: malformed below
      on_frame(f, n == CANFD_MTU, now);
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
            ingest.set_link_down(false);
            ingest.count_recovery();
            backoff = config.min_backoff;
          } else {
            next_open = std::chrono::steady_clock::now() + backoff;
            backoff = std::min(backoff * 2, config.max_backoff);
          }
        }
      }
      std::array<pollfd, 2> fds{{{wake_fd, POLLIN, 0}, {s, POLLIN, 0}}};
      const int nfds = s >= 0 ? 2 : 1;
      const int ready =
          ::poll(fds.data(), static_cast<nfds_t>(nfds), static_cast<int>(kPollTick.count()));
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
          ingest.set_link_down(true);
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
  if (m.config.interface.empty() || m.config.interface.size() >= IFNAMSIZ ||
      m.config.base_id + 15 > CAN_SFF_MASK ||
      m.config.min_backoff <= std::chrono::milliseconds(0) ||
      m.config.max_backoff < m.config.min_backoff)
    return Status::kInvalidConfig;
  bool any = false;
  for (float s : m.config.scale) any |= s != 0.0f;
  if (!any) return Status::kInvalidConfig;
  const int s = m.open_socket();
  if (s < 0) return Status::kIoError;
  m.sock = s;
  m.wake_fd = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (m.wake_fd < 0) return Status::kIoError;
  m.ingest.start(m.clock.now());
  if (m.thread.start(m.config.thread, [&m] { m.run(); }) != Status::kOk) return Status::kIoError;
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
  if (m.ingest.bus_off()) return Status::kBusOff;
  return Status::kNoData;
}

CmsStreamStats SocketCanCmsStream::stats() const { return impl_->ingest.stats(); }

Status SocketCanCmsStream::health(Timestamp now) const { return impl_->ingest.health(now); }

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

const ThreadReport& SocketCanCmsStream::thread_report() const { return impl_->thread.report(); }

}  // namespace hal
