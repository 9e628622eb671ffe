// The twin's Modbus results server (hal::ModbusResultsServer) inside the rig,
// read by the host's mbpoll through QEMU's port forward (tools/rig/README.md,
// "Modbus over the emulated network"). Publishes the paper's check point and
// announces what the first registers of map v1 must read.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>

#include "hal/modbus_results_server.hpp"

int main() {
  const char* port_env = std::getenv("DRIVETWIN_RIG_MODBUS_PORT");
  const int port = port_env ? std::atoi(port_env) : 0;
  if (port <= 0 || port > 65535) {
    std::fprintf(stderr, "rigd_modbus_results: DRIVETWIN_RIG_MODBUS_PORT='%s' is not a TCP port\n",
                 port_env ? port_env : "");
    return 2;
  }
  hal::ModbusServerConfig c;
  c.register_count = 166;  // a test image; hal does not know what the registers mean
  c.command_start = 150;
  c.command_count = 16;
  c.bind_address = "0.0.0.0";
  c.port = static_cast<std::uint16_t>(port);
  hal::ModbusResultsServer server(c);
  if (server.configure() != hal::Status::kOk || server.activate() != hal::Status::kOk) {
    std::fprintf(stderr, "rigd_modbus_results: cannot listen on 0.0.0.0:%d\n", port);
    return 1;
  }
  // The application's header layout (app/results/register_map.hpp), written by hand.
  constexpr auto kU16 = hal::RegisterType::kUInt16;
  constexpr auto kHigh = hal::WordOrder::kHighWordFirst;
  hal::RegisterImage r;
  r.count = c.register_count;
  bool ok = hal::put_register(r, 0, kU16, kHigh, 1);
  ok &= hal::put_register(r, 1, kU16, kHigh, 33);  // running | calibrated
  ok &= hal::put_register(r, 2, kU16, kHigh, 0);
  ok &= hal::put_register(r, 3, kU16, kHigh, 7);
  ok &= hal::put_register(r, 4, hal::RegisterType::kUInt32, kHigh, 1);
  // 0x48B0 0xA260 at registers 8-9 (1-based 9-10)
  ok &= hal::put_register(r, 8, hal::RegisterType::kFloat32, kHigh, 361747.0);
  if (!ok || server.publish(r) != hal::Status::kOk) return 1;
  // Registers 0..3 (1-based 1..4): map version, status, fault, calibration; then 8..9.
  std::printf("RIG-READY modbus rigd_modbus_results port=%d ref=1 values=1,33,0,7\n", port);
  std::fflush(stdout);
  while (true) std::this_thread::sleep_for(std::chrono::seconds(1));
}
