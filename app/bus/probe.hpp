#pragma once
// `drivetwin bus probe`: open the configured buses and print, live, what
// arrives — SCADA values with units and age, CMS blocks per second per channel
// with gaps and errors, keyphasor speed — so an engineer at the cabinet can see
// that the wiring and the register map are right before the twin runs.
// Outputs are held in their safe states; the results server (if configured)
// serves the register map with the status word 0 (not running).
// What it checks and how it exits: run_probe().
//
// Thread context: a command on the main thread; not real-time.

#include <chrono>
#include <iosfwd>

#include "bus/bus_config.hpp"
#include "model/drivetrain/description.hpp"

namespace app::bus {

struct ProbeOptions {
  double seconds = 10.0;  // [s] how long to listen (recording time for replay)
  std::chrono::milliseconds report_every{1000};  // print period
  std::chrono::milliseconds tick{10};            // how often the buses are drained
  bool fast = false;                             // replay/sim only: step time instead of waiting
  model::Drivetrain drivetrain = model::paper_2mw();  // ratios for the speed cross-check
};

/// Runs the probe, printing to `out`. Every bus is opened and probed on its own: one that
/// cannot be opened is reported and the others are still probed. At the end:
///   - stale: a bus whose status is not ok at the end (SCADA, CMS health);
///   - stuck: SCADA wind and rotor speed identical update after update; CMS blocks
///     repeated (duplicates); keyphasor edges without a valid speed;
///   - inconsistent: every redundant rotor speed — SCADA rotor speed, SCADA generator
///     speed through the overall ratio, the keyphasor through its shaft's ratio and
///     pulses_per_rev, the CMS gear-mesh lines (recording/bundle_check.hpp's search, at
///     the sample rate the blocks' source time stamps give) — within 3 % of their median;
/// each problem printed with what to look at. Lost CMS blocks (gaps) and a bus status that
/// means lost data (gap, bus errors, overflow) are printed as warnings, not failures.
/// @return 0 when every input delivered data and nothing is wrong, 3 when one never
///         delivered (and nothing else is wrong), 4 when a bus failed to open or is
///         stale, stuck or inconsistent.
/// @throws BusConfigError only for a wrong combination of options (--fast with live buses).
int run_probe(const BusConfig& config, const ProbeOptions& options, std::ostream& out);

}  // namespace app::bus
