#pragma once
// Load spectra per operating point for history mode (years of SCADA rows without
// running the dynamics per row).
//
// Once per drivetrain and calibration, a LoadSimulator produces the load time series at
// each point of a (rotor torque, rotor speed) grid; each series runs through a
// DamageAccumulator, and the grid stores the resulting damage per ROTOR REVOLUTION of every
// channel. A SCADA row then costs one interpolation per channel: D += d(T, n)·revs.
// Interpolation: bilinear in log d over (torque, speed) (damage ∝ σ^m with σ ∝ T^½ or T is
// a power law, which log-interpolation follows closely); a cell with a zero corner is
// interpolated linearly in d instead. One exp per channel and row.
//
// Sources:
//  - kDynamics: the simulator runs the dynamics model (mesh forces and bearing reactions
//    over a window at constant mean torque and speed).
//  - kQuasiStatic: FALLBACK, named as such wherever it is used: the loads are the
//    quasi-static mesh forces of ChannelSet::quasi_static_loads (torque / base radius,
//    equal planet load sharing) with the application factor K_A of the ChannelSet; no
//    dynamic content at all.
//
// Thread context: start-up / host only (allocates). damage_per_rev() is allocation-free.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "model/fatigue/damage_accumulator.hpp"
#include "model/fatigue/drivetrain_channels.hpp"

namespace model::fatigue {

enum class SpectrumSource : std::uint8_t { kQuasiStatic, kDynamics };
const char* spectrum_source_name(SpectrumSource source);

struct SpectrumGrid {
  double torque_max_nm = 0.0;        // [N·m] grid spans [0, torque_max]
  std::uint32_t torque_points = 61;  // [-] ≥ 2
  double speed_min_rpm = 0.5;        // [rpm] > 0 (damage per revolution is undefined at 0)
  double speed_max_rpm = 0.0;        // [rpm]
  std::uint32_t speed_points = 12;   // [-] ≥ 2
  double torque_at(std::uint32_t i) const;
  double speed_at(std::uint32_t j) const;
};

/// One operating point's load history, at constant mean rotor torque and speed.
struct LoadSeries {
  double dt_s = 0.0;  // [s] sample period
  std::vector<LoadSample> samples;
  std::vector<double> rotor_rpm;  // [rpm] per sample
};

/// Fills `out` for (rotor torque [N·m], rotor speed [rpm]); false on failure.
using LoadSimulator = std::function<bool(double torque_nm, double rotor_rpm, LoadSeries& out)>;

struct LoadSpectrum {
  SpectrumGrid grid;
  SpectrumSource source = SpectrumSource::kQuasiStatic;
  std::size_t channel_count = 0;
  std::vector<double> damage_per_rev;  // [(i·speed_points + j)·channel_count + c] [-/rotor rev]
  std::vector<double> log_damage_per_rev;  // ln of the above (−inf where 0); see prepare()

  /// Fills log_damage_per_rev from damage_per_rev (after building or loading).
  void prepare();

  /// Interpolated damage per rotor revolution of every channel at (torque, speed), clamped
  /// to the grid; writes channel_count values to out.
  void damage_per_rev_at(double torque_nm, double rotor_rpm, double* out) const;
};

/// Damage per rotor revolution of every channel at one operating point: `simulator`'s load
/// history through a DamageAccumulator (what build_load_spectrum() does at each grid point).
/// Writes channels.channel_count() values; false with `error` naming the point on failure.
bool damage_per_rev_at_point(const ChannelSet& channels, const LoadSimulator& simulator,
                             double torque_nm, double rotor_rpm, double* out, std::string* error);

/// Runs `simulator` at every grid point; empty spectrum (channel_count 0) on failure,
/// with `error` naming the grid point.
LoadSpectrum build_load_spectrum(const ChannelSet& channels, const SpectrumGrid& grid,
                                 SpectrumSource source, const LoadSimulator& simulator,
                                 std::string* error);

/// The quasi-static FALLBACK simulator: one sample of ChannelSet::quasi_static_loads.
LoadSimulator quasi_static_simulator(const ChannelSet& channels);

}  // namespace model::fatigue
