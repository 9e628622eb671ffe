// `drivetwin bus probe --config FILE [--seconds S] [--fast]`: commissioning aid
// that opens the configured buses and prints what arrives (app/bus/probe.hpp).
#include <iostream>
#include <memory>
#include <string>

#include "bus/bus_config.hpp"
#include "bus/probe.hpp"
#include "cli/command.hpp"
#include "cli/options.hpp"
#include "config/drivetrain_file.hpp"

namespace {

struct Options {
  std::string config;
  std::string drivetrain;
  double seconds = 10.0;
  double every_s = 1.0;
  bool fast = false;
};

void setup_bus(CLI::App& sub) {
  sub.require_subcommand(1);
  auto opts = std::make_shared<Options>();
  CLI::App* probe = sub.add_subcommand(
      "probe",
      "Open the configured buses and print live what arrives: SCADA values with units and age, "
      "CMS blocks/s with gaps and errors, keyphasor speed");
  probe
      ->add_option("--config", opts->config,
                   "bus configuration file (TOML, drivetwin-bus/1; see hal/README.md)")
      ->required();
  probe->add_option("--seconds", opts->seconds, "how long to listen [s] (default 10)")
      ->check(app::cli::number_in(0.01, 1e6, "s"));
  probe->add_option("--every", opts->every_s, "print period [s] (default 1)")
      ->check(app::cli::number_in(0.01, 3600.0, "s"));
  app::config::add_drivetrain_option(*probe, opts->drivetrain)
      ->description(
          "Drivetrain whose ratios the redundant speeds are cross-checked with: a built-in name "
          "or a TOML file (default paper-2mw)");
  probe->add_flag("--fast", opts->fast,
                  "replay/sim buses only: step time as fast as possible instead of waiting");
  probe->callback([opts] {
    try {
      const app::bus::BusConfig config = app::bus::load_bus_config(opts->config);
      app::bus::ProbeOptions po;
      po.seconds = opts->seconds;
      po.report_every = std::chrono::milliseconds(static_cast<long>(opts->every_s * 1000.0));
      po.fast = opts->fast;
      po.drivetrain = app::config::load_drivetrain(opts->drivetrain);
      app::cli::exit_status() = app::bus::run_probe(config, po, std::cout);
    } catch (const app::bus::BusConfigError& e) {
      throw app::cli::CommandError(e.what());
    }
  });
}

const bool kBusProbeRegistered = app::cli::register_command(
    {"bus", "Turbine bus tools (bus probe: commissioning check of the wiring)", &setup_bus});

}  // namespace
