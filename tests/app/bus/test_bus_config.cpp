// The bus configuration file (drivetwin-bus/1): the shipped example parses into
// the values written in it; every kind of mistake is named by file, line and key.
#include <gtest/gtest.h>

#include "bus/bus_config.hpp"

namespace {

using app::bus::Backend;
using app::bus::BusConfigError;

std::string error_of(const std::string& toml) {
  try {
    (void)app::bus::parse_bus_config(toml, "test.toml");
  } catch (const BusConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(BusConfig, TheReferenceTurbineExampleParsesIntoItsWrittenValues) {
  // Arrange
  const std::string file = std::string(DRIVETWIN_SOURCE_DIR) + "/app/data/bus/bus-paper-2mw.toml";

  // Act
  const app::bus::BusConfig c = app::bus::load_bus_config(file);

  // Assert
  EXPECT_EQ(c.scada, Backend::kLinux);
  EXPECT_EQ(c.modbus_client.host, "192.168.10.2");
  ASSERT_EQ(c.modbus_client.map.count, 7u);
  const hal::ScadaRegister& torque = c.modbus_client.map.entries[5];
  EXPECT_EQ(torque.quantity, hal::ScadaQuantity::kRotorTorque);
  EXPECT_EQ(torque.spec.address, 8);
  EXPECT_EQ(torque.spec.type, hal::RegisterType::kInt32);
  EXPECT_EQ(c.modbus_client.map.entries[6].spec.function, hal::RegisterFunction::kInput);
  ASSERT_TRUE(c.modbus_client.map.invalid_mask);
  EXPECT_EQ(c.modbus_client.map.invalid_mask->address, 40);
  EXPECT_EQ(c.cms, Backend::kLinux);
  EXPECT_EQ(c.socketcan.base_id, 0x180u);
  EXPECT_FLOAT_EQ(c.socketcan.scale[1], 0.001f);
  EXPECT_EQ(c.cms_channels[1].name, "point2");
  EXPECT_EQ(c.gpio_outputs.alarm_line, 2u);
  EXPECT_EQ(c.modbus_server.writable, std::vector<std::uint16_t>{150});
  EXPECT_EQ(c.modbus_server.allow, std::vector<std::string>{"192.168.10.2"});
}

TEST(BusConfig, NamesTheLineAndKeyOfAWrongRegisterType) {
  const std::string e = error_of(R"(format = "drivetwin-bus/1"
[scada]
backend = "modbus"
[[scada.register]]
quantity = "wind_speed_mps"
address = 0
type = "float64"
unit = "m/s"
)");
  EXPECT_NE(e.find("test.toml:7: scada.register[0].type: 'float64'; expected int16, uint16, int32, "
                   "uint32 or float32"),
            std::string::npos)
      << e;
}

TEST(BusConfig, RejectsAUnitThatDoesNotMatchTheQuantity) {
  const std::string e = error_of(R"(format = "drivetwin-bus/1"
[scada]
backend = "modbus"
[[scada.register]]
quantity = "torque_nm"
address = 0
unit = "kN·m"
)");
  EXPECT_NE(e.find("scada.register[0].unit: 'kN·m'; expected 'N·m'"), std::string::npos) << e;
}

TEST(BusConfig, RejectsUnknownKeysSoTyposDoNotPassSilently) {
  const std::string e =
      error_of("format = \"drivetwin-bus/1\"\n[cms]\nbackend = \"sim\"\nintreface = \"can0\"\n");
  EXPECT_NE(e.find("test.toml:4: cms.intreface: unknown key"), std::string::npos) << e;
}

TEST(BusConfig, RejectsOverlappingRegisters) {
  const std::string e = error_of(R"(format = "drivetwin-bus/1"
[scada]
backend = "modbus"
[[scada.register]]
quantity = "wind_speed_mps"
address = 0
type = "float32"
unit = "m/s"
[[scada.register]]
quantity = "rotor_speed_rpm"
address = 1
unit = "rpm"
)");
  EXPECT_NE(e.find("scada.register[1]: overlaps"), std::string::npos) << e;
}

TEST(BusConfig, RejectsAWrongFormatVersionAndBadTomlWithPosition) {
  EXPECT_NE(error_of("format = \"drivetwin-bus/2\"\n")
                .find("format: 'drivetwin-bus/2'; expected \"drivetwin-bus/1\""),
            std::string::npos);
  EXPECT_NE(error_of("format = \"drivetwin-bus/1\"\n[scada\n").find("test.toml:2:"),
            std::string::npos)
      << error_of("format = \"drivetwin-bus/1\"\n[scada\n");
}

TEST(BusConfig, RejectsWritableResultRegisters) {
  const std::string e =
      error_of("format = \"drivetwin-bus/1\"\n[results]\nbackend = \"modbus\"\nwritable = [8]\n");
  EXPECT_NE(e.find("results.writable: expected command register addresses 150..165"),
            std::string::npos)
      << e;
}

TEST(BusConfig, ReplayWithoutABundleIsAnError) {
  const std::string e = error_of("format = \"drivetwin-bus/1\"\n[cms]\nbackend = \"replay\"\n");
  EXPECT_NE(e.find("replay.bundle: missing"), std::string::npos) << e;
}

TEST(BusConfig, ReportsAMissingFile) {
  EXPECT_THROW((void)app::bus::load_bus_config("no/such/bus.toml"), BusConfigError);
}

}  // namespace
