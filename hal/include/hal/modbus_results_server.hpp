#pragma once
// Modbus TCP server exposing a register image (hal/results_sink.hpp) to the turbine
// controller / SCADA. What the registers mean is the application's register map; the
// server only knows how many registers there are and which block clients may write.
//
// - Read-only by default: FC 03 and FC 04 read the image (the same registers as
//   holding and input registers); writes are refused with exception 01 (illegal
//   function). When `writable` lists registers of the command block, FC 06/16 may
//   write those and only those (others: exception 02, illegal data address). The
//   command block is served from what clients wrote, not from the published image.
//   Coil/discrete functions: exception 01.
// - Addresses at or beyond register_count: exception 02.
// - Optional allow-list of client IPv4 addresses; others are disconnected on accept.
// - At most max_connections clients; further connections are accepted and
//   closed at once. A client that sends a malformed frame (bad MBAP header) or
//   stops reading is disconnected; the others are not disturbed.
// - The server thread never blocks on one client: sockets are non-blocking,
//   frames are assembled per connection.
//
// Thread context: publish() from the RT thread (wait-free, LatestValue);
// configure/activate/deactivate from the control thread; one internal server thread.

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "hal/modbus_codec.hpp"
#include "hal/results_sink.hpp"
#include "hal/thread.hpp"

namespace hal {

struct ModbusServerConfig {
  std::string bind_address = "127.0.0.1";  // "0.0.0.0" for all interfaces
  std::uint16_t port = 1502;               // 0: ephemeral (see bound_port())
  int unit_id = 1;                         // answered unit id (0xFF and 0 also accepted)
  WordOrder word_order = WordOrder::kHighWordFirst;
  int max_connections = 4;
  std::vector<std::string> allow;       // client IPv4 addresses; empty = anyone
  std::uint16_t register_count = 0;     // registers served (1..kMaxImageRegisters)
  std::uint16_t command_start = 0;      // first register of the command block
  std::uint16_t command_count = 0;      // registers in it (≤ kMaxCommandRegisters; 0: none)
  std::vector<std::uint16_t> writable;  // registers (absolute addresses, inside the command
                                        // block) clients may write
  std::chrono::milliseconds idle_timeout{60000};  // close a connection silent for this long
  // The server thread (app/ passes its thread table's entry).
  ThreadAttributes thread{"dt-results", SchedPolicy::kOther, 0, -1, 0};
};

/// Registers a command block can have.
inline constexpr std::size_t kMaxCommandRegisters = 64;

/// What clients wrote into the command registers (last values; values[k] is register
/// command_start + k).
struct ModbusCommands {
  std::array<std::uint16_t, kMaxCommandRegisters> values{};
  std::uint32_t writes = 0;  // accepted write requests so far
};

/// Counters (wait-free snapshot).
struct ModbusServerStats {
  std::uint64_t requests = 0;
  std::uint64_t exceptions = 0;  // exception responses sent
  std::uint64_t malformed = 0;   // connections dropped for a malformed frame
  std::uint64_t rejected = 0;    // connections refused (limit or allow-list)
  std::uint64_t accepted = 0;
  int open_connections = 0;
};

class ModbusResultsServer final : public ResultsSink {
 public:
  explicit ModbusResultsServer(const ModbusServerConfig& config);
  ~ModbusResultsServer() override;
  ModbusResultsServer(const ModbusResultsServer&) = delete;
  ModbusResultsServer& operator=(const ModbusResultsServer&) = delete;

  /// Binds and listens (port 0: an ephemeral port), allocates, starts the thread.
  Status configure() override;
  /// Starts answering requests (before: connections wait in the backlog).
  Status activate() override;
  /// Stops answering, closes every client connection; keeps the listening socket.
  Status deactivate() override;
  LifecycleState state() const override;
  Status publish(const RegisterImage& image) override;

  std::uint16_t bound_port() const;
  ModbusCommands commands() const;
  ModbusServerStats stats() const;
  /// What the OS granted the I/O thread (valid after configure(); warning names refusals).
  const ThreadReport& thread_report() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hal
