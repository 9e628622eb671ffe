#pragma once
// The bus configuration file (TOML, format `drivetwin-bus/1`): which backend
// serves each of the box's I/O (SCADA source, CMS stream, keyphasor, digital
// outputs, results server) and how it is wired. Documented key by key in
// hal/README.md ("Bus configuration file"); example for the reference turbine:
// app/data/bus/bus-paper-2mw.toml.
//
// Errors: BusConfigError, whose message names the file, the line, the dotted
// key (e.g. `scada.register[2].type`) and what was expected.
//
// Thread context: start-up only (allocates, throws); never on the RT path.

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "hal/gpiod_lines.hpp"
#include "hal/modbus_results_server.hpp"
#include "hal/modbus_scada_source.hpp"
#include "hal/sim_backends.hpp"
#include "hal/socketcan_cms_stream.hpp"

namespace app::bus {

inline constexpr const char* kBusFormat = "drivetwin-bus/1";

class BusConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class Backend { kNone, kLinux, kReplay, kSim };  // linux: modbus / socketcan / gpio

struct ChannelInfo {
  std::string name;  // e.g. "point1"
  std::string unit;  // e.g. "m/s^2"
};

struct BusConfig {
  std::filesystem::path file;  // the config file (relative paths resolve against its folder)

  Backend scada = Backend::kNone;
  hal::ModbusClientConfig modbus_client;
  std::string scada_csv;                 // replay: a SCADA CSV export (else the bundle's scada.csv)
  std::string scada_columns = "bundle";  // replay: column mapping (hal/scada_csv.hpp)
  hal::SimFault scada_fault = hal::SimFault::kNone;

  Backend cms = Backend::kNone;
  hal::SocketCanConfig socketcan;
  std::vector<ChannelInfo> cms_channels;  // by channel id (index); names and units for display
  hal::SimFault cms_fault = hal::SimFault::kNone;

  Backend keyphasor = Backend::kNone;
  hal::GpiodKeyphasorConfig gpio_keyphasor;
  int pulses_per_rev = 1;
  std::string keyphasor_shaft = "hss";
  hal::SimFault keyphasor_fault = hal::SimFault::kNone;

  Backend outputs = Backend::kNone;  // linux (gpio) or sim (memory)
  hal::GpiodOutputsConfig gpio_outputs;

  Backend results = Backend::kNone;  // linux (modbus server)
  hal::ModbusServerConfig modbus_server;

  std::string bundle;         // replay: recording bundle directory (resolved)
  double replay_speed = 1.0;  // replay: 1 = real time, > 1 faster
};

/// Parses and validates a bus configuration file.
BusConfig load_bus_config(const std::filesystem::path& file);
/// Parses TOML text; `name` stands for the file in messages and relative paths
/// resolve against its parent folder.
BusConfig parse_bus_config(std::string_view text, const std::filesystem::path& name);

const char* to_string(Backend b);

}  // namespace app::bus
