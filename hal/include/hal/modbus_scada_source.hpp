#pragma once
// SCADA source polling the turbine controller over Modbus TCP (or RTU) with
// libmodbus, on an I/O thread of its own. The RT thread only copies the latest
// snapshot (LatestValue), so a slow, silent or vanished controller never blocks
// the loop: it shows up as kStale / kDisconnected and error counts.
//
// Reconnection: after a failed transaction the connection is closed and
// re-opened with exponential back-off (min_backoff, doubling, up to
// max_backoff); deactivate() interrupts a back-off wait at once.
//
// Thread context: configure/activate/deactivate from the control thread;
// read() from the RT thread (wait-free copy); the poll thread is internal.

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "hal/clock.hpp"
#include "hal/modbus_codec.hpp"
#include "hal/scada_source.hpp"
#include "hal/thread.hpp"

namespace hal {

struct ModbusClientConfig {
  enum class Transport : std::uint8_t { kTcp, kRtu };
  Transport transport = Transport::kTcp;
  // TCP
  std::string host = "127.0.0.1";
  std::uint16_t port = 502;
  // RTU
  std::string device = "/dev/ttyS0";
  int baud = 19200;
  char parity = 'E';  // 'N', 'E', 'O'
  int data_bits = 8;
  int stop_bits = 1;
  // Both
  int unit_id = 1;  // Modbus slave / unit id
  std::chrono::milliseconds poll_period{1000};
  std::chrono::milliseconds response_timeout{200};
  std::chrono::milliseconds min_backoff{100};
  std::chrono::milliseconds max_backoff{5000};
  std::chrono::milliseconds stale_after{3000};  // data older than this → kStale
  std::uint16_t max_hole = 8;                   // registers read across to merge two reads
  ScadaRegisterMap map;
  // The poll thread (app/ passes its thread table's entry).
  ThreadAttributes thread{"dt-scada", SchedPolicy::kOther, 0, -1, 0};
};

class ModbusScadaSource final : public ScadaSource {
 public:
  /// @param clock  stamps received data; must outlive this object (thread-safe now()).
  ModbusScadaSource(const ModbusClientConfig& config, const Clock& clock);
  ~ModbusScadaSource() override;
  ModbusScadaSource(const ModbusScadaSource&) = delete;
  ModbusScadaSource& operator=(const ModbusScadaSource&) = delete;

  /// Validates the map, creates the libmodbus context and the poll thread
  /// (idle until activate). Does not need the controller to be reachable.
  Status configure() override;
  Status activate() override;
  Status deactivate() override;
  LifecycleState state() const override;
  Status read(Timestamp now, ScadaData& out) override;

  /// True while the poll thread holds a working connection (for diagnostics).
  bool connected() const;
  /// What the OS granted the I/O thread (valid after configure(); warning names refusals).
  const ThreadReport& thread_report() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hal
