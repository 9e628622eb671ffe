// Modbus TCP results server: see hal/modbus_results_server.hpp for the contract
// and hal/README.md for the register map.
//
// libmodbus is used for what it is good at (decoding a request PDU and building
// the response with modbus_reply on a mapping), not for I/O: its
// modbus_receive() would block the server on a client that sends half a frame.
// Instead each connection is a non-blocking socket whose bytes are assembled
// into MBAP frames here, then handed to modbus_reply().
#include "hal/modbus_results_server.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <modbus.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <mutex>

#include "hal/latest_value.hpp"

namespace hal {
namespace {

constexpr std::size_t kMbapHeader = 7;  // transaction(2) protocol(2) length(2) unit(1)
constexpr std::size_t kMaxAdu = MODBUS_TCP_MAX_ADU_LENGTH;  // 260
constexpr int kMaxConnectionsLimit = 32;                    // hard cap on max_connections
constexpr std::chrono::milliseconds kPollTick{100};

// Function codes that write registers / coils.
bool is_register_write(std::uint8_t fc) {
  return fc == 0x06 || fc == 0x10 || fc == 0x16 || fc == 0x17;
}

std::uint16_t be16(const std::uint8_t* p) { return static_cast<std::uint16_t>((p[0] << 8) | p[1]); }

struct Connection {
  int fd = -1;
  std::array<std::uint8_t, kMaxAdu> buf{};
  std::size_t len = 0;
  std::chrono::steady_clock::time_point last_activity{};
};

}  // namespace

struct ModbusResultsServer::Impl {
  explicit Impl(const ModbusServerConfig& c) : config(c) {}

  ModbusServerConfig config;
  std::atomic<LifecycleState> lifecycle{LifecycleState::kUnconfigured};
  int listen_fd = -1;
  int wake_fd = -1;
  std::uint16_t port = 0;
  modbus_t* ctx = nullptr;  // only for modbus_reply / modbus_reply_exception
  modbus_mapping_t* mapping = nullptr;
  std::array<Connection, kMaxConnectionsLimit> conns{};
  std::array<in_addr_t, 64> allow{};
  std::size_t allow_count = 0;
  RegisterImage image{};  // server thread only
  LatestValue<RegisterImage> latest;
  LatestValue<ModbusCommands> commands_out;
  ModbusCommands commands{};  // server thread only
  std::atomic<std::uint64_t> requests{0}, exceptions{0}, malformed{0}, rejected{0}, accepted{0};
  std::atomic<int> open{0};
  std::atomic<bool> active{false};
  std::atomic<bool> stop{false};
  Thread thread;

  bool writable(std::uint16_t addr) const {
    return std::find(config.writable.begin(), config.writable.end(), addr) != config.writable.end();
  }

  void close_conn(Connection& c) {
    if (c.fd < 0) return;
    ::close(c.fd);
    c.fd = -1;
    c.len = 0;
    --open;
  }

  void close_all() {
    for (auto& c : conns)
      if (c.fd >= 0) close_conn(c);
  }

  bool in_command_block(std::uint32_t a) const {
    return a >= config.command_start &&
           a < std::uint32_t{config.command_start} + config.command_count;
  }
  void refresh_image() {
    if (!latest.read(image)) return;  // nothing published yet: the registers stay zero
    const std::uint16_t n = std::min(image.count, config.register_count);
    for (std::uint16_t a = 0; a < n; ++a) {
      if (in_command_block(a)) continue;  // clients' values, not the image's
      mapping->tab_registers[a] = image.words[a];
      mapping->tab_input_registers[a] = image.words[a];
    }
  }

  void send_exception(Connection& c, const std::uint8_t* req, int code) {
    modbus_set_socket(ctx, c.fd);
    ++exceptions;
    if (modbus_reply_exception(ctx, req, static_cast<unsigned>(code)) < 0) close_conn(c);
  }

  /// Answers one complete ADU. @return false if the connection was closed.
  bool handle(Connection& c, std::size_t adu_len) {
    ++requests;
    const std::uint8_t* req = c.buf.data();
    const std::uint8_t unit = req[6];
    const std::uint8_t fc = req[7];
    if (unit != config.unit_id && unit != 0 && unit != 0xFF) {
      send_exception(c, req, MODBUS_EXCEPTION_GATEWAY_TARGET);
      return c.fd >= 0;
    }
    if (is_register_write(fc)) {
      if (config.writable.empty()) {
        send_exception(c, req, MODBUS_EXCEPTION_ILLEGAL_FUNCTION);
        return c.fd >= 0;
      }
      // Which registers would be written?
      std::uint16_t start = 0, count = 0;
      if (fc == 0x06 || fc == 0x16) {
        if (adu_len < kMbapHeader + 3) return malformed_frame(c);
        start = be16(req + 8);
        count = 1;
      } else if (fc == 0x10) {
        if (adu_len < kMbapHeader + 5) return malformed_frame(c);
        start = be16(req + 8);
        count = be16(req + 10);
      } else {  // 0x17 read/write multiple: write part at bytes 12..15
        if (adu_len < kMbapHeader + 9) return malformed_frame(c);
        start = be16(req + 12);
        count = be16(req + 14);
      }
      for (std::uint32_t a = start; a < std::uint32_t{start} + count; ++a) {
        if (a > 0xFFFF || !writable(static_cast<std::uint16_t>(a))) {
          send_exception(c, req, MODBUS_EXCEPTION_ILLEGAL_DATA_ADDRESS);
          return c.fd >= 0;
        }
      }
    } else if (fc == 0x03 || fc == 0x04) {
      if (adu_len < kMbapHeader + 5) return malformed_frame(c);
      const std::uint16_t start = be16(req + 8);
      const std::uint16_t count = be16(req + 10);
      if (count < 1 || count > MODBUS_MAX_READ_REGISTERS) {
        send_exception(c, req, MODBUS_EXCEPTION_ILLEGAL_DATA_VALUE);
        return c.fd >= 0;
      }
      if (std::uint32_t{start} + count > config.register_count) {
        send_exception(c, req, MODBUS_EXCEPTION_ILLEGAL_DATA_ADDRESS);
        return c.fd >= 0;
      }
    } else {
      send_exception(c, req, MODBUS_EXCEPTION_ILLEGAL_FUNCTION);
      return c.fd >= 0;
    }
    refresh_image();
    modbus_set_socket(ctx, c.fd);
    // Requests reaching here are in range; modbus_reply builds the response
    // (and still range-checks FC 16's quantity against the byte count).
    if (modbus_reply(ctx, req, static_cast<int>(adu_len), mapping) < 0) {
      close_conn(c);
      return false;
    }
    if (is_register_write(fc)) {
      for (std::uint16_t k = 0; k < config.command_count; ++k)
        commands.values[k] = mapping->tab_registers[config.command_start + k];
      ++commands.writes;
      commands_out.write(commands);
    }
    return true;
  }

  bool malformed_frame(Connection& c) {
    ++malformed;
    close_conn(c);
    return false;
  }

  void on_readable(Connection& c) {
    while (c.fd >= 0) {
      const ssize_t n = ::recv(c.fd, c.buf.data() + c.len, c.buf.size() - c.len, 0);
      if (n == 0) {
        close_conn(c);
        return;
      }
      if (n < 0) {
        if (errno == EAGAIN || errno == EWOULDBLOCK) return;
        if (errno == EINTR) continue;
        close_conn(c);
        return;
      }
      c.len += static_cast<std::size_t>(n);
      c.last_activity = std::chrono::steady_clock::now();
      // Answer every complete frame in the buffer.
      while (c.fd >= 0 && c.len >= kMbapHeader) {
        const std::uint16_t protocol = be16(c.buf.data() + 2);
        const std::uint16_t length = be16(c.buf.data() + 4);  // unit id + PDU
        if (protocol != 0 || length < 2 || length > kMaxAdu - 6) {
          malformed_frame(c);
          return;
        }
        const std::size_t adu = 6 + std::size_t{length};
        if (c.len < adu) break;
        if (!active.load()) {
          c.len = 0;  // deactivated: drop requests
          break;
        }
        if (!handle(c, adu)) return;
        std::memmove(c.buf.data(), c.buf.data() + adu, c.len - adu);
        c.len -= adu;
      }
    }
  }

  void on_accept() {
    while (true) {
      sockaddr_in peer{};
      socklen_t plen = sizeof peer;
      const int fd = ::accept4(listen_fd, reinterpret_cast<sockaddr*>(&peer), &plen,
                               SOCK_NONBLOCK | SOCK_CLOEXEC);
      if (fd < 0) return;  // EAGAIN: backlog drained
      ++accepted;
      bool allowed = allow_count == 0;
      for (std::size_t i = 0; i < allow_count; ++i)
        if (allow[i] == peer.sin_addr.s_addr) allowed = true;
      Connection* slot = nullptr;
      if (open.load() < config.max_connections) {
        for (auto& c : conns) {
          if (c.fd < 0) {
            slot = &c;
            break;
          }
        }
      }
      if (!allowed || slot == nullptr || !active.load()) {
        ++rejected;
        ::close(fd);
        continue;
      }
      const int one = 1;
      ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
      slot->fd = fd;
      slot->len = 0;
      slot->last_activity = std::chrono::steady_clock::now();
      ++open;
    }
  }

  void run() {
    std::array<pollfd, kMaxConnectionsLimit + 2> fds{};
    std::array<Connection*, kMaxConnectionsLimit + 2> owner{};
    while (!stop.load()) {
      std::size_t n = 0;
      fds[n] = {wake_fd, POLLIN, 0};
      owner[n++] = nullptr;
      fds[n] = {listen_fd, POLLIN, 0};
      owner[n++] = nullptr;
      for (auto& c : conns) {
        if (c.fd >= 0) {
          fds[n] = {c.fd, POLLIN, 0};
          owner[n++] = &c;
        }
      }
      const int ready = ::poll(fds.data(), n, static_cast<int>(kPollTick.count()));
      if (ready < 0 && errno != EINTR) break;
      if (fds[0].revents & POLLIN) {
        std::uint64_t v;
        [[maybe_unused]] const ssize_t r = ::read(wake_fd, &v, sizeof v);
      }
      if (!active.load()) {
        close_all();
      }
      if (fds[1].revents & POLLIN) on_accept();
      for (std::size_t i = 2; i < n; ++i) {
        Connection* c = owner[i];
        if (c->fd < 0) continue;
        if (fds[i].revents & (POLLERR | POLLHUP | POLLNVAL)) {
          if (!(fds[i].revents & POLLIN)) {
            close_conn(*c);
            continue;
          }
        }
        if (fds[i].revents & POLLIN) on_readable(*c);
      }
      const auto now = std::chrono::steady_clock::now();
      for (auto& c : conns)
        if (c.fd >= 0 && now - c.last_activity > config.idle_timeout) close_conn(c);
    }
    close_all();
  }

  void wake() {
    const std::uint64_t one = 1;
    [[maybe_unused]] const ssize_t r = ::write(wake_fd, &one, sizeof one);
  }
};

ModbusResultsServer::ModbusResultsServer(const ModbusServerConfig& config)
    : impl_(std::make_unique<Impl>(config)) {}

ModbusResultsServer::~ModbusResultsServer() {
  Impl& m = *impl_;
  if (m.thread.joinable()) {
    m.stop = true;
    m.wake();
    m.thread.join();
  }
  if (m.listen_fd >= 0) ::close(m.listen_fd);
  if (m.wake_fd >= 0) ::close(m.wake_fd);
  if (m.mapping) modbus_mapping_free(m.mapping);
  if (m.ctx) modbus_free(m.ctx);
}

Status ModbusResultsServer::configure() {
  Impl& m = *impl_;
  if (m.lifecycle != LifecycleState::kUnconfigured) return Status::kWrongState;
  const ModbusServerConfig& c = m.config;
  if (c.max_connections < 1 || c.max_connections > kMaxConnectionsLimit || c.unit_id < 1 ||
      c.unit_id > 247 || c.allow.size() > m.allow.size())
    return Status::kInvalidConfig;
  if (c.register_count < 1 || c.register_count > kMaxImageRegisters ||
      c.command_count > kMaxCommandRegisters ||
      std::uint32_t{c.command_start} + c.command_count > c.register_count)
    return Status::kInvalidConfig;
  for (auto a : c.writable)
    if (!m.in_command_block(a)) return Status::kInvalidConfig;
  for (const auto& s : c.allow) {
    in_addr addr{};
    if (::inet_pton(AF_INET, s.c_str(), &addr) != 1) return Status::kInvalidConfig;
    m.allow[m.allow_count++] = addr.s_addr;
  }
  sockaddr_in sa{};
  sa.sin_family = AF_INET;
  sa.sin_port = htons(c.port);
  if (::inet_pton(AF_INET, c.bind_address.c_str(), &sa.sin_addr) != 1)
    return Status::kInvalidConfig;

  m.ctx = modbus_new_tcp("127.0.0.1", 0);  // never connects; only formats replies
  m.mapping =
      modbus_mapping_new_start_address(0, 0, 0, 0, 0, c.register_count, 0, c.register_count);
  if (!m.ctx || !m.mapping) return Status::kIoError;

  m.listen_fd = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (m.listen_fd < 0) return Status::kIoError;
  const int one = 1;
  ::setsockopt(m.listen_fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  if (::bind(m.listen_fd, reinterpret_cast<sockaddr*>(&sa), sizeof sa) != 0 ||
      ::listen(m.listen_fd, 16) != 0) {
    ::close(m.listen_fd);
    m.listen_fd = -1;
    return Status::kIoError;
  }
  socklen_t len = sizeof sa;
  ::getsockname(m.listen_fd, reinterpret_cast<sockaddr*>(&sa), &len);
  m.port = ntohs(sa.sin_port);
  m.wake_fd = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (m.wake_fd < 0) return Status::kIoError;
  if (m.thread.start(m.config.thread, [&m] { m.run(); }) != Status::kOk) return Status::kIoError;
  m.lifecycle = LifecycleState::kInactive;
  return Status::kOk;
}

Status ModbusResultsServer::activate() {
  Impl& m = *impl_;
  if (m.lifecycle == LifecycleState::kUnconfigured) return Status::kWrongState;
  m.active = true;
  m.wake();
  m.lifecycle = LifecycleState::kActive;
  return Status::kOk;
}

Status ModbusResultsServer::deactivate() {
  Impl& m = *impl_;
  if (m.lifecycle == LifecycleState::kUnconfigured) return Status::kOk;
  m.active = false;
  m.wake();
  m.lifecycle = LifecycleState::kInactive;
  return Status::kOk;
}

LifecycleState ModbusResultsServer::state() const { return impl_->lifecycle; }

Status ModbusResultsServer::publish(const RegisterImage& image) {
  if (impl_->lifecycle == LifecycleState::kUnconfigured) return Status::kWrongState;
  impl_->latest.write(image);
  return Status::kOk;
}

std::uint16_t ModbusResultsServer::bound_port() const { return impl_->port; }

ModbusCommands ModbusResultsServer::commands() const {
  ModbusCommands c{};
  (void)impl_->commands_out.read(c);
  return c;
}

ModbusServerStats ModbusResultsServer::stats() const {
  const Impl& m = *impl_;
  return ModbusServerStats{m.requests.load(), m.exceptions.load(), m.malformed.load(),
                           m.rejected.load(), m.accepted.load(),   m.open.load()};
}

const ThreadReport& ModbusResultsServer::thread_report() const { return impl_->thread.report(); }

}  // namespace hal
