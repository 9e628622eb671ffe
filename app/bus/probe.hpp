#pragma once
// `drivetwin bus probe`: open the configured buses and print, live, what
// arrives — SCADA values with units and age, CMS blocks per second per channel
// with gaps and errors, keyphasor speed — so an engineer at the cabinet can see
// that the wiring and the register map are right before the twin runs.
// Outputs are held in their safe states; the results server (if configured)
// serves the register map with the status word 0 (not running).
//
// Thread context: a command on the main thread; not real-time.

#include <chrono>
#include <iosfwd>

#include "bus/bus_config.hpp"

namespace app::bus {

struct ProbeOptions {
  double seconds = 10.0;  // [s] how long to listen (recording time for replay)
  std::chrono::milliseconds report_every{1000};  // print period
  std::chrono::milliseconds tick{10};            // how often the buses are drained
  bool fast = false;                             // replay/sim only: step time instead of waiting
};

/// Runs the probe, printing to `out`.
/// @return 0 when every configured input delivered data, 3 when one never did.
/// @throws BusConfigError / std::runtime_error when a bus cannot be opened (names bus and setting).
int run_probe(const BusConfig& config, const ProbeOptions& options, std::ostream& out);

}  // namespace app::bus
