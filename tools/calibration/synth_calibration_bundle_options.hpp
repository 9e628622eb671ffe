#pragma once
// synth_calibration_bundle's command line (validated: tools/common/options.hpp).
#include <CLI/CLI.hpp>

#include <cstdint>
#include <string>

#include "common/options.hpp"

namespace tools::calibration {

struct SynthCalibrationOptions {
  std::string out;
  double rpm = 8.33;            // [rpm]
  double torque = 361747.0;     // [N·m]
  double damping_factor = 2.0;  // [-] Rayleigh η and ζ × this
  double mesh_scale = 0.8;      // [-]
  double bearing_scale = 1.3;   // [-]
  double noise = 0.05;          // [-] of each point's RMS
  double duration_s = 6.0;      // [s]
  double fs_hz = 25600.0;       // [Hz]
  double settle_s = 0.5;        // [s]
  bool tacho = false;
  std::uint64_t seed = 1;
  std::string fault;
  std::string model_name = "full";
};

inline void add_options(CLI::App& cli, SynthCalibrationOptions& o,
                        const tools::options::OperatingRange& range) {
  namespace opt = tools::options;
  cli.add_option("--out", o.out, "Bundle directory to write")->required();
  cli.add_option("--rpm", o.rpm, "Rotor speed [rpm]")->check(opt::rotor_speed(range));
  cli.add_option("--torque", o.torque, "Rotor torque [N·m]")->check(opt::rotor_torque(range));
  cli.add_option("--damping-factor", o.damping_factor,
                 "Rayleigh eta and zeta × this, relative to nominal")
      ->check(opt::scale_factor());
  cli.add_option("--mesh-scale", o.mesh_scale, "Mesh stiffness scale of every stage")
      ->check(opt::scale_factor());
  cli.add_option("--bearing-scale", o.bearing_scale, "Bearing stiffness scale of every shaft")
      ->check(opt::scale_factor());
  cli.add_option("--noise", o.noise, "White noise RMS as a fraction of each point's RMS")
      ->check(opt::noise_ratio());
  cli.add_option("--duration", o.duration_s, "Length [s]")->check(opt::recording_length());
  cli.add_option("--fs", o.fs_hz, "Sample rate [Hz]")->check(opt::vibration_rate());
  cli.add_flag("--tacho", o.tacho, "Add a once-per-revolution tacho channel on the hss");
  cli.add_option("--seed", o.seed, "Noise seed")->check(opt::seed());
  cli.add_option("--model", o.model_name,
                 "full (default: full-order Newmark model), rom, or lumped (stand-in)")
      ->check(opt::one_of({"full", "rom", "lumped"}));
  cli.add_option("--settle", o.settle_s,
                 "full/rom: seconds simulated and discarded before the recording [s]")
      ->check(opt::number_in(0.0, 60.0, "s"));
  cli.add_option(
      "--fault", o.fault,
      "flat:<channel> (constant), clip:<channel> (saturate at 60 % of the peak), drop:<channel>");
}

}  // namespace tools::calibration
