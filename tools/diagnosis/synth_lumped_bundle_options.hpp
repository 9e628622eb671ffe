#pragma once
// synth_lumped_bundle's command line (validated: tools/common/options.hpp). The effect's
// own parameters (a crack's stiffness loss below one, ...) are checked by the effect
// (model/drivetrain/effects.hpp) once the effect and its location are known.
#include <CLI/CLI.hpp>

#include <string>

#include "common/options.hpp"

namespace tools::diagnosis {

struct SynthLumpedOptions {
  std::string out, effect, location;
  double severity = 0.0;        // [effect's unit]
  double rpm = 8.33;            // [rpm]
  double torque = 361747.0;     // [N·m]
  double duration = 30.0;       // [s]
  double fs = 25600.0;          // [Hz]
  double drift = 0.02;          // [-]
  double drift_period = 23.0;   // [s]
  double noise = 0.05;          // [-]
  double gain_error = 0.1;      // [-]
  double stiffness = 1.0;       // [-]
  double damping = 1.0;         // [-]
  double slip = 0.01;           // [-]
  double damping_ratio = 0.02;  // [-]
  bool tacho = false, conceal = false;
  unsigned seed = 1;
};

inline void add_options(CLI::App& cli, SynthLumpedOptions& o,
                        const tools::options::OperatingRange& range) {
  namespace opt = tools::options;
  cli.add_option("--out", o.out, "Bundle directory to write")->required();
  cli.add_option("--effect", o.effect, "Effect id of the diagnosis contract (none when absent)");
  cli.add_option("--location", o.location, "Component id");
  cli.add_option(
         "--severity", o.severity,
         "crack: stiffness loss; eccentricity [m]; bearing: impact force [N]; unbalance [kg·m]; "
         "misalignment [N]; planet pass: depth; resonance: frequency [Hz]")
      ->check(opt::non_negative());
  cli.add_option("--rpm", o.rpm, "Mean rotor speed [rpm]")->check(opt::rotor_speed(range));
  cli.add_option("--torque", o.torque, "Rotor torque [N·m]")->check(opt::rotor_torque(range));
  cli.add_option("--duration", o.duration, "Length [s]")->check(opt::recording_length());
  cli.add_option("--fs", o.fs, "Sample rate [Hz]")->check(opt::vibration_rate());
  cli.add_option("--drift", o.drift, "Relative amplitude of the slow speed drift")
      ->check(opt::fraction_below_one());
  cli.add_option("--drift-period", o.drift_period, "Period of the speed drift [s]")
      ->check(opt::positive("s"));
  cli.add_option("--noise", o.noise, "White noise RMS as a fraction of each channel's RMS")
      ->check(opt::noise_ratio());
  cli.add_option("--gain-error", o.gain_error, "Sensor gain error: each channel × (1 ± up to this)")
      ->check(opt::fraction_below_one());
  cli.add_flag("--tacho", o.tacho, "Add a once-per-revolution tacho channel on the hss");
  cli.add_option("--stiffness-scale", o.stiffness,
                 "Every mesh and bearing stiffness × this (parameter drift)")
      ->check(opt::scale_factor());
  cli.add_option("--damping-scale", o.damping, "Damping × this (parameter drift)")
      ->check(opt::scale_factor());
  cli.add_option("--slip", o.slip, "Bearing defects: rolling-element slip")
      ->check(opt::fraction_below_one());
  cli.add_option("--damping-ratio", o.damping_ratio, "Housing resonance: damping ratio")
      ->check(opt::number_in(0.0, 1.0, "", true, true));
  cli.add_option("--seed", o.seed, "Noise, gain, jitter and drift-phase seed")->check(opt::seed());
  cli.add_flag("--conceal", o.conceal,
               "Scale the severity (up to 8 tries) until concealed with an 8–20 dB margin");
}

}  // namespace tools::diagnosis
