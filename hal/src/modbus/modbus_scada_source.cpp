// Modbus SCADA client: libmodbus on a poll thread of its own; see
// hal/modbus_scada_source.hpp for the contract.
#include "hal/modbus_scada_source.hpp"

#include <modbus.h>

#include <atomic>
#include <cerrno>
#include <condition_variable>
#include <mutex>

#include "hal/latest_value.hpp"

namespace hal {

struct ModbusScadaSource::Impl {
  Impl(const ModbusClientConfig& c, const Clock& clk) : config(c), clock(clk) {}

  ModbusClientConfig config;
  const Clock& clock;
  std::atomic<LifecycleState> lifecycle{LifecycleState::kUnconfigured};
  modbus_t* ctx = nullptr;
  std::array<ReadBlock, kMaxReadBlocks> blocks{};
  std::size_t block_count = 0;
  std::array<std::array<std::uint16_t, kMaxReadRegisters>, kMaxReadBlocks> buffers{};

  LatestValue<ScadaData> latest;
  ScadaData working{};  // poll thread only
  std::atomic<bool> is_connected{false};

  std::mutex mutex;
  std::condition_variable cv;
  bool active = false;  // guarded by mutex
  bool stop = false;    // guarded by mutex
  Thread thread;

  /// Waits up to `d`; returns false if the thread must stop or the source was deactivated.
  bool wait_for(std::chrono::milliseconds d) {
    std::unique_lock lock(mutex);
    cv.wait_for(lock, d, [&] { return stop || !active; });
    return !stop && active;
  }

  void disconnect() {
    if (is_connected.load()) modbus_close(ctx);
    is_connected = false;
  }

  bool poll_once() {
    for (std::size_t b = 0; b < block_count; ++b) {
      const ReadBlock& blk = blocks[b];
      const int n = blk.function == RegisterFunction::kHolding
                        ? modbus_read_registers(ctx, blk.start, blk.count, buffers[b].data())
                        : modbus_read_input_registers(ctx, blk.start, blk.count, buffers[b].data());
      if (n != blk.count) return false;
    }
    const Timestamp now = clock.now();
    std::uint16_t invalid_mask = 0;
    if (config.map.invalid_mask) {
      const std::uint16_t* r = locate(*config.map.invalid_mask);
      if (r != nullptr) invalid_mask = *r;
    }
    for (std::size_t i = 0; i < config.map.count; ++i) {
      const ScadaRegister& e = config.map.entries[i];
      const std::uint16_t* r = locate(e.spec);
      Measurement& m = working[e.quantity];
      const auto v = r ? decode_register(e.spec, r, register_count(e.spec.type)) : std::nullopt;
      const bool flagged = (invalid_mask >> static_cast<unsigned>(e.quantity)) & 1u;
      if (!v) ++working.error_count;
      m.value = v.value_or(m.value);
      m.stamp = now;
      m.valid = v.has_value() && !flagged;
    }
    working.last_update = now;
    ++working.update_count;
    latest.write(working);
    return true;
  }

  const std::uint16_t* locate(const RegisterSpec& s) const {
    for (std::size_t b = 0; b < block_count; ++b) {
      const ReadBlock& blk = blocks[b];
      if (blk.function == s.function && s.address >= blk.start &&
          s.address + register_count(s.type) <= std::size_t{blk.start} + blk.count)
        return &buffers[b][s.address - blk.start];
    }
    return nullptr;
  }

  void run() {
    std::chrono::milliseconds backoff = config.min_backoff;
    while (true) {
      bool run_now;
      {
        std::lock_guard lock(mutex);
        run_now = stop || active;
      }
      if (!run_now) disconnect();  // deactivated: free the controller's connection slot
      {
        std::unique_lock lock(mutex);
        cv.wait(lock, [&] { return stop || active; });
        if (stop) break;
      }
      if (!is_connected.load()) {
        if (modbus_connect(ctx) != 0) {
          ++working.error_count;
          latest.write(working);
          if (!wait_for(backoff)) {
            continue;
          }
          backoff = std::min(backoff * 2, config.max_backoff);
          continue;
        }
        is_connected = true;
        if (working.update_count > 0 || working.error_count > 0) ++working.reconnect_count;
      }
      const auto started = std::chrono::steady_clock::now();
      if (!poll_once()) {
        ++working.error_count;
        latest.write(working);
        disconnect();
        if (!wait_for(backoff)) continue;
        backoff = std::min(backoff * 2, config.max_backoff);
        continue;
      }
      backoff = config.min_backoff;
      const auto spent = std::chrono::duration_cast<std::chrono::milliseconds>(
          std::chrono::steady_clock::now() - started);
      wait_for(spent < config.poll_period ? config.poll_period - spent
                                          : std::chrono::milliseconds(0));
    }
    disconnect();
  }
};

ModbusScadaSource::ModbusScadaSource(const ModbusClientConfig& config, const Clock& clock)
    : impl_(std::make_unique<Impl>(config, clock)) {}

ModbusScadaSource::~ModbusScadaSource() {
  if (impl_->thread.joinable()) {
    {
      std::lock_guard lock(impl_->mutex);
      impl_->stop = true;
    }
    impl_->cv.notify_all();
    impl_->thread.join();
  }
  if (impl_->ctx) modbus_free(impl_->ctx);
}

Status ModbusScadaSource::configure() {
  Impl& m = *impl_;
  if (m.lifecycle != LifecycleState::kUnconfigured) return Status::kWrongState;
  const ModbusClientConfig& c = m.config;
  if (validate_map(c.map) || c.map.count == 0 || c.unit_id < 0 || c.unit_id > 247 ||
      c.poll_period <= std::chrono::milliseconds(0) ||
      c.response_timeout <= std::chrono::milliseconds(0) ||
      c.min_backoff <= std::chrono::milliseconds(0) || c.max_backoff < c.min_backoff)
    return Status::kInvalidConfig;
  m.block_count = plan_reads(c.map, c.max_hole, m.blocks);
  if (c.transport == ModbusClientConfig::Transport::kTcp) {
    m.ctx = modbus_new_tcp(c.host.c_str(), c.port);
  } else {
    m.ctx = modbus_new_rtu(c.device.c_str(), c.baud, c.parity, c.data_bits, c.stop_bits);
  }
  if (m.ctx == nullptr) return Status::kInvalidConfig;
  if (modbus_set_slave(m.ctx, c.unit_id) != 0) return Status::kInvalidConfig;
  const auto us = std::chrono::duration_cast<std::chrono::microseconds>(c.response_timeout).count();
  modbus_set_response_timeout(m.ctx, static_cast<std::uint32_t>(us / 1000000),
                              static_cast<std::uint32_t>(us % 1000000));
  modbus_set_byte_timeout(m.ctx, static_cast<std::uint32_t>(us / 1000000),
                          static_cast<std::uint32_t>(us % 1000000));
  if (m.thread.start(m.config.thread, [&m] { m.run(); }) != Status::kOk) return Status::kIoError;
  m.lifecycle = LifecycleState::kInactive;
  return Status::kOk;
}

Status ModbusScadaSource::activate() {
  Impl& m = *impl_;
  if (m.lifecycle == LifecycleState::kUnconfigured) return Status::kWrongState;
  {
    std::lock_guard lock(m.mutex);
    m.active = true;
  }
  m.cv.notify_all();
  m.lifecycle = LifecycleState::kActive;
  return Status::kOk;
}

Status ModbusScadaSource::deactivate() {
  Impl& m = *impl_;
  if (m.lifecycle == LifecycleState::kUnconfigured) return Status::kOk;
  {
    std::lock_guard lock(m.mutex);
    m.active = false;
  }
  m.cv.notify_all();
  m.lifecycle = LifecycleState::kInactive;
  return Status::kOk;
}

LifecycleState ModbusScadaSource::state() const { return impl_->lifecycle; }

bool ModbusScadaSource::connected() const { return impl_->is_connected.load(); }

Status ModbusScadaSource::read(Timestamp now, ScadaData& out) {
  Impl& m = *impl_;
  if (m.lifecycle != LifecycleState::kActive) return Status::kWrongState;
  ScadaData snap;
  if (!m.latest.read(snap)) return Status::kNoData;
  out = snap;
  if (snap.update_count == 0) return m.is_connected ? Status::kNoData : Status::kDisconnected;
  if (!m.is_connected) return Status::kDisconnected;
  if (now - snap.last_update > m.config.stale_after) return Status::kStale;
  return Status::kOk;
}

const ThreadReport& ModbusScadaSource::thread_report() const { return impl_->thread.report(); }

}  // namespace hal
