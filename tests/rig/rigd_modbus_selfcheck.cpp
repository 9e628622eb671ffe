// A Modbus TCP server inside the emulated rig that the host reads with Debian's
// mbpoll through QEMU's user-mode port forward (tools/rig/README.md, "Modbus over
// the emulated network"). It proves the network path of the rig itself: guest
// virtio-net, hostfwd, a libmodbus server on aarch64, an independent client on the
// host. It serves a fixed table of holding registers, announces the table on
// stdout in the rig's RIG-READY format, and serves one client at a time until it
// is killed. Not a drivetwin component: the results server lives in hal/.

#include <modbus/modbus.h>

#include <array>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include <unistd.h>

namespace {
// Register 1 (mbpoll's 1-based reference) onwards. Small, distinct, non-negative
// values so that a shifted, truncated or byte-swapped read cannot match.
constexpr std::array<std::uint16_t, 8> kTable{2026, 1502, 4660, 1, 22136, 0, 30000, 7};
}  // namespace

int main() {
  const char* port_env = std::getenv("DRIVETWIN_RIG_MODBUS_PORT");
  const int port = port_env != nullptr ? std::atoi(port_env) : 0;
  if (port <= 0 || port > 65535) {
    std::fprintf(stderr,
                 "rigd_modbus_selfcheck: DRIVETWIN_RIG_MODBUS_PORT='%s' is not a TCP port\n",
                 port_env != nullptr ? port_env : "");
    return 2;
  }
  modbus_t* ctx = modbus_new_tcp("0.0.0.0", port);
  modbus_mapping_t* map = modbus_mapping_new(0, 0, static_cast<int>(kTable.size()), 0);
  if (ctx == nullptr || map == nullptr) {
    std::fprintf(stderr, "rigd_modbus_selfcheck: libmodbus: %s\n", modbus_strerror(errno));
    return 2;
  }
  for (std::size_t i = 0; i < kTable.size(); ++i) map->tab_registers[i] = kTable[i];
  const int listener = modbus_tcp_listen(ctx, 1);
  if (listener < 0) {
    std::fprintf(stderr, "rigd_modbus_selfcheck: listen on port %d: %s\n", port,
                 modbus_strerror(errno));
    return 2;
  }
  std::string values;
  for (std::size_t i = 0; i < kTable.size(); ++i) {
    values += (i == 0 ? "" : ",") + std::to_string(kTable[i]);
  }
  std::printf("RIG-READY modbus rigd_modbus_selfcheck port=%d ref=1 values=%s\n", port,
              values.c_str());
  std::fflush(stdout);

  int listen_fd = listener;
  for (;;) {
    if (modbus_tcp_accept(ctx, &listen_fd) < 0) continue;
    std::array<std::uint8_t, MODBUS_TCP_MAX_ADU_LENGTH> query{};
    for (;;) {
      const int n = modbus_receive(ctx, query.data());
      if (n > 0) {
        modbus_reply(ctx, query.data(), n, map);
      } else if (n < 0) {
        break;  // client gone: close and wait for the next one
      }
    }
    modbus_close(ctx);
  }
}
