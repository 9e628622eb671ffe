// ModbusScadaSource against a real libmodbus slave on loopback: register map,
// word orders, scaling, timeouts, a controller that vanishes and returns.
#include <gtest/gtest.h>

#include "../no_alloc.hpp"
#include "hal/modbus_scada_source.hpp"
#include "modbus_test_util.hpp"

namespace {

using namespace std::chrono_literals;
using hal::ScadaQuantity;
using hal::Status;
using modbus_test::PeerServer;
using modbus_test::wait_until;

void add(hal::ScadaRegisterMap& m, ScadaQuantity q, std::uint16_t addr, hal::RegisterType t,
         hal::RegisterFunction f = hal::RegisterFunction::kHolding,
         hal::WordOrder o = hal::WordOrder::kHighWordFirst, double scale = 1.0,
         double offset = 0.0) {
  hal::ScadaRegister& e = m.entries[m.count++];
  e.quantity = q;
  e.spec.address = addr;
  e.spec.type = t;
  e.spec.function = f;
  e.spec.word_order = o;
  e.spec.scale = scale;
  e.spec.offset = offset;
}

hal::ModbusClientConfig fast_config(std::uint16_t port) {
  hal::ModbusClientConfig c;
  c.port = port;
  c.poll_period = 20ms;
  c.response_timeout = 100ms;
  c.min_backoff = 20ms;
  c.max_backoff = 200ms;
  c.stale_after = 400ms;
  return c;
}

TEST(ModbusScadaSource, ReadsEveryTypeWordOrderAndScaleOfTheMap) {
  // Arrange: the controller's registers, filled by hand
  PeerServer peer;
  ASSERT_TRUE(peer.bound());
  peer.set_holding(100, 675);     // wind: uint16, 0.01 m/s/LSB → 6.75 m/s
  peer.set_holding(101, 0x4105);  // rotor speed: float32 ABCD 8.33f = 0x410547AE
  peer.set_holding(102, 0x47AE);
  peer.set_holding(103, 0xA260);  // torque: float32 CDAB 361747.0f = 0x48B0A260
  peer.set_holding(104, 0x48B0);
  peer.set_input(10, static_cast<std::uint16_t>(-25));  // pitch: int16 × 0.1 → −2.5°
  peer.set_input(11, 0xFFFF);  // power: int32 ABCD × 0.1: 0xFFFF FC18 = −1000 → −100 kW
  peer.set_input(12, 0xFC18);
  hal::ModbusClientConfig c = fast_config(peer.port());
  add(c.map, ScadaQuantity::kWindSpeed, 100, hal::RegisterType::kUInt16,
      hal::RegisterFunction::kHolding, hal::WordOrder::kHighWordFirst, 0.01);
  add(c.map, ScadaQuantity::kRotorSpeed, 101, hal::RegisterType::kFloat32);
  add(c.map, ScadaQuantity::kRotorTorque, 103, hal::RegisterType::kFloat32,
      hal::RegisterFunction::kHolding, hal::WordOrder::kLowWordFirst);
  add(c.map, ScadaQuantity::kPitch, 10, hal::RegisterType::kInt16, hal::RegisterFunction::kInput,
      hal::WordOrder::kHighWordFirst, 0.1);
  add(c.map, ScadaQuantity::kPower, 11, hal::RegisterType::kInt32, hal::RegisterFunction::kInput,
      hal::WordOrder::kHighWordFirst, 0.1);
  hal::MonotonicClock clock;
  hal::ModbusScadaSource source(c, clock);

  // Act
  ASSERT_EQ(source.configure(), Status::kOk);
  ASSERT_EQ(source.activate(), Status::kOk);
  hal::ScadaData d;
  const bool got = wait_until([&] { return source.read(clock.now(), d) == Status::kOk; });

  // Assert
  ASSERT_TRUE(got);
  EXPECT_NEAR(d[ScadaQuantity::kWindSpeed].value, 6.75, 1e-12);
  EXPECT_NEAR(d[ScadaQuantity::kRotorSpeed].value, 8.33, 1e-6);
  EXPECT_EQ(d[ScadaQuantity::kRotorTorque].value, 361747.0);
  EXPECT_NEAR(d[ScadaQuantity::kPitch].value, -2.5, 1e-12);
  EXPECT_NEAR(d[ScadaQuantity::kPower].value, -100.0, 1e-9);
  EXPECT_TRUE(d[ScadaQuantity::kPower].valid);
  EXPECT_FALSE(d[ScadaQuantity::kYawError].valid);  // not in the map
  EXPECT_EQ(source.deactivate(), Status::kOk);
}

TEST(ModbusScadaSource, ReadOnTheLoopThreadAllocatesNothing) {
  // Arrange: polling a live controller on its own thread
  PeerServer peer;
  peer.set_holding(0, 675);
  hal::ModbusClientConfig c = fast_config(peer.port());
  add(c.map, ScadaQuantity::kWindSpeed, 0, hal::RegisterType::kUInt16);
  hal::MonotonicClock clock;
  hal::ModbusScadaSource source(c, clock);
  ASSERT_EQ(source.configure(), Status::kOk);
  ASSERT_EQ(source.activate(), Status::kOk);
  hal::ScadaData d;
  ASSERT_TRUE(wait_until([&] { return source.read(clock.now(), d) == Status::kOk; }));

  // Act: the loop thread reads while the poll thread keeps publishing
  no_alloc::Scope scope;
  int ok = 0;
  for (int i = 0; i < 2000; ++i) ok += source.read(clock.now(), d) == Status::kOk;

  // Assert
  EXPECT_EQ(scope.allocations(), 0u);
  EXPECT_GT(ok, 0);
}

TEST(ModbusScadaSource, MarksQuantitiesTheControllerFlagsInvalid) {
  // Arrange: invalid-mask register 200, bit 0 (wind speed) set
  PeerServer peer;
  peer.set_holding(100, 675);
  peer.set_holding(101, 8);
  peer.set_holding(200, 0x0001);
  hal::ModbusClientConfig c = fast_config(peer.port());
  add(c.map, ScadaQuantity::kWindSpeed, 100, hal::RegisterType::kUInt16);
  add(c.map, ScadaQuantity::kRotorSpeed, 101, hal::RegisterType::kUInt16);
  hal::RegisterSpec mask;
  mask.address = 200;
  c.map.invalid_mask = mask;
  hal::MonotonicClock clock;
  hal::ModbusScadaSource source(c, clock);
  ASSERT_EQ(source.configure(), Status::kOk);
  ASSERT_EQ(source.activate(), Status::kOk);

  // Act
  hal::ScadaData d;
  ASSERT_TRUE(wait_until([&] { return source.read(clock.now(), d) == Status::kOk; }));

  // Assert
  EXPECT_FALSE(d[ScadaQuantity::kWindSpeed].valid);
  EXPECT_TRUE(d[ScadaQuantity::kRotorSpeed].valid);
}

TEST(ModbusScadaSource, ReportsASilentControllerAsStaleWithoutBlockingTheReader) {
  // Arrange: a controller that accepts the connection and never answers
  PeerServer peer(0, /*silent=*/true);
  hal::ModbusClientConfig c = fast_config(peer.port());
  add(c.map, ScadaQuantity::kWindSpeed, 0, hal::RegisterType::kUInt16);
  hal::MonotonicClock clock;
  hal::ModbusScadaSource source(c, clock);
  ASSERT_EQ(source.configure(), Status::kOk);
  ASSERT_EQ(source.activate(), Status::kOk);

  // Act: read in a tight loop while the poll thread sits in its timeouts
  hal::ScadaData d;
  Status last = Status::kOk;
  long reads = 0;
  const bool errors_seen = wait_until([&] {
    last = source.read(clock.now(), d);
    ++reads;
    return d.error_count >= 2;
  });

  // Assert: timeouts counted as errors, never data; reads kept returning
  EXPECT_TRUE(errors_seen);
  EXPECT_NE(last, Status::kOk);
  EXPECT_EQ(d.update_count, 0u);
  EXPECT_GT(reads, 2);
}

TEST(ModbusScadaSource, RecoversWhenTheControllerVanishesAndReturnsOnTheSamePort) {
  // Arrange
  auto peer = std::make_unique<PeerServer>();
  const std::uint16_t port = peer->port();
  peer->set_holding(0, 500);
  hal::ModbusClientConfig c = fast_config(port);
  add(c.map, ScadaQuantity::kWindSpeed, 0, hal::RegisterType::kUInt16,
      hal::RegisterFunction::kHolding, hal::WordOrder::kHighWordFirst, 0.01);
  hal::MonotonicClock clock;
  hal::ModbusScadaSource source(c, clock);
  ASSERT_EQ(source.configure(), Status::kOk);
  ASSERT_EQ(source.activate(), Status::kOk);
  hal::ScadaData d;
  ASSERT_TRUE(wait_until([&] { return source.read(clock.now(), d) == Status::kOk; }));

  // Act 1: the controller goes away
  peer.reset();
  const bool noticed = wait_until([&] {
    const Status s = source.read(clock.now(), d);
    return s == Status::kDisconnected || s == Status::kStale;
  });
  const std::uint32_t errors_while_down = d.error_count;

  // Act 2: it comes back with a new value
  peer = std::make_unique<PeerServer>(port);
  ASSERT_TRUE(peer->bound()) << "port " << port << " not free again";
  peer->set_holding(0, 725);
  const bool back = wait_until([&] {
    return source.read(clock.now(), d) == Status::kOk && d[ScadaQuantity::kWindSpeed].value > 7.0;
  });

  // Assert
  EXPECT_TRUE(noticed);
  EXPECT_GE(errors_while_down, 1u);
  ASSERT_TRUE(back);
  EXPECT_NEAR(d[ScadaQuantity::kWindSpeed].value, 7.25, 1e-12);
  EXPECT_GE(d.reconnect_count, 1u);
}

TEST(ModbusScadaSource, RejectsAnOverlappingMapAtConfigure) {
  // Arrange
  hal::ModbusClientConfig c = fast_config(1);
  add(c.map, ScadaQuantity::kWindSpeed, 0, hal::RegisterType::kFloat32);
  add(c.map, ScadaQuantity::kRotorSpeed, 1, hal::RegisterType::kUInt16);
  hal::MonotonicClock clock;
  hal::ModbusScadaSource source(c, clock);

  // Act / Assert
  EXPECT_EQ(source.configure(), Status::kInvalidConfig);
  EXPECT_EQ(source.state(), hal::LifecycleState::kUnconfigured);
}

TEST(ModbusScadaSource, RefusesToReadBeforeActivate) {
  PeerServer peer;
  hal::ModbusClientConfig c = fast_config(peer.port());
  add(c.map, ScadaQuantity::kWindSpeed, 0, hal::RegisterType::kUInt16);
  hal::MonotonicClock clock;
  hal::ModbusScadaSource source(c, clock);
  ASSERT_EQ(source.configure(), Status::kOk);
  hal::ScadaData d;
  EXPECT_EQ(source.read(clock.now(), d), Status::kWrongState);
}

}  // namespace
