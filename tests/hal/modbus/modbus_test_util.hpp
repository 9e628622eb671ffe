#pragma once
// Helpers for the Modbus loopback tests: a libmodbus-based controller stand-in
// (the independent peer the client is tested against) and polling waits.
#include <arpa/inet.h>
#include <modbus.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>

namespace modbus_test {

/// Polls `pred` every 5 ms until true or `limit` passes. Generous limits: the
/// same tests run under ASan and qemu-aarch64.
inline bool wait_until(const std::function<bool()>& pred,
                       std::chrono::milliseconds limit = std::chrono::milliseconds(10000)) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < end) {
    if (pred()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return pred();
}

/// A Modbus TCP slave made of plain libmodbus (modbus_receive + modbus_reply on
/// a mapping), listening on 127.0.0.1. Port 0 picks an ephemeral port.
/// `silent`: accepts connections but never answers (a hung controller).
class PeerServer {
 public:
  explicit PeerServer(std::uint16_t port = 0, bool silent = false) : silent_(silent) {
    ctx_ = modbus_new_tcp("127.0.0.1", 0);
    mapping_ = modbus_mapping_new(0, 0, 1000, 1000);
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    const int one = 1;
    ::setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    sockaddr_in sa{};
    sa.sin_family = AF_INET;
    sa.sin_port = htons(port);
    sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    bound_ = ::bind(fd_, reinterpret_cast<sockaddr*>(&sa), sizeof sa) == 0 && ::listen(fd_, 4) == 0;
    socklen_t len = sizeof sa;
    ::getsockname(fd_, reinterpret_cast<sockaddr*>(&sa), &len);
    port_ = ntohs(sa.sin_port);
    thread_ = std::thread([this] { run(); });
  }
  ~PeerServer() {
    stop_ = true;
    thread_.join();
    ::close(fd_);
    modbus_mapping_free(mapping_);
    modbus_free(ctx_);
  }
  bool bound() const { return bound_; }
  std::uint16_t port() const { return port_; }
  void set_holding(int addr, std::uint16_t v) {
    std::lock_guard lock(mutex_);
    mapping_->tab_registers[addr] = v;
  }
  void set_input(int addr, std::uint16_t v) {
    std::lock_guard lock(mutex_);
    mapping_->tab_input_registers[addr] = v;
  }
  int requests() const { return requests_.load(); }

 private:
  void run() {
    while (!stop_) {
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, 20) <= 0) continue;
      const int client = ::accept(fd_, nullptr, nullptr);
      if (client < 0) continue;
      serve(client);
      ::close(client);
    }
  }
  void serve(int client) {
    modbus_set_socket(ctx_, client);
    std::uint8_t query[MODBUS_TCP_MAX_ADU_LENGTH];
    while (!stop_) {
      pollfd p{client, POLLIN, 0};
      if (::poll(&p, 1, 20) <= 0) continue;
      if (silent_) {
        char sink[256];
        if (::recv(client, sink, sizeof sink, 0) <= 0) return;
        continue;
      }
      const int n = modbus_receive(ctx_, query);
      if (n < 0) return;  // peer closed or bad frame
      if (n == 0) continue;
      ++requests_;
      std::lock_guard lock(mutex_);
      modbus_reply(ctx_, query, n, mapping_);
    }
  }

  bool silent_;
  modbus_t* ctx_ = nullptr;
  modbus_mapping_t* mapping_ = nullptr;
  int fd_ = -1;
  bool bound_ = false;
  std::uint16_t port_ = 0;
  std::atomic<bool> stop_{false};
  std::atomic<int> requests_{0};
  std::mutex mutex_;
  std::thread thread_;
};

}  // namespace modbus_test
