// synth_lumped_bundle: a recording bundle (drivetwin-recording/1) from the independent
// lumped gearbox model (lumped_gearbox.hpp) with one effect of the diagnosis contract,
// plus what a real measurement adds: white sensor noise, a slow ±drift of the speed, a
// gain error per channel, a tacho or none, parameters off nominal. Prints the case's
// concealment figures (concealment.hpp): the effect is simulated once more without
// itself to measure them.
//
//   synth_lumped_bundle --out DIR [--effect ID --location LOC --severity X] [--rpm 8.33]
//       [--torque 361747] [--duration 30] [--fs 25600] [--drift 0.02] [--drift-period 23]
//       [--noise 0.05] [--gain-error 0.1] [--tacho] [--stiffness-scale 1] [--damping-scale 1]
//       [--slip 0.01] [--damping-ratio 0.02] [--seed 1] [--conceal]
// Writes DIR/truth.json beside the bundle (the case's ground truth).
// Host tool: allocates and throws (caught here: message and status 1).
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <exception>
#include <string>

#include <filesystem>
#include <fstream>

#include "hal/recording_bundle.hpp"
#include "lumped_case.hpp"
#include "model/drivetrain/description.hpp"
#include "synth_lumped_bundle_options.hpp"

namespace {

int run(int argc, char** argv) {
  CLI::App cli{"Recording bundle from the independent lumped gearbox model with one effect"};
  tools::diagnosis::SynthLumpedOptions o;
  tools::diagnosis::add_options(cli, o, tools::options::operating_range(model::paper_2mw()));
  CLI11_PARSE(cli, argc, argv);
  const std::string &out = o.out, &effect = o.effect, &location = o.location;
  const double severity = o.severity, rpm = o.rpm, torque = o.torque, duration = o.duration,
               fs = o.fs, drift = o.drift, drift_period = o.drift_period, noise = o.noise,
               gain_error = o.gain_error, stiffness = o.stiffness, damping = o.damping,
               slip = o.slip, damping_ratio = o.damping_ratio;
  const bool tacho = o.tacho, conceal = o.conceal;
  const unsigned seed = o.seed;

  tools::diagnosis::LumpedCaseSpec spec;
  spec.id = out;
  spec.effect = {effect, location, severity, slip, damping_ratio};
  spec.rpm = rpm;
  spec.torque_nm = torque;
  spec.seconds = duration;
  spec.fs_hz = fs;
  spec.drift = drift;
  spec.drift_period_s = drift_period;
  spec.noise = noise;
  spec.gain_error = gain_error;
  spec.tacho = tacho;
  spec.stiffness_scale = stiffness;
  spec.damping_scale = damping;
  spec.conceal = conceal;
  spec.seed = seed;
  const tools::diagnosis::LumpedCase c =
      tools::diagnosis::make_lumped_case(model::paper_2mw(), spec);
  if (!effect.empty()) {
    std::printf(
        "concealment: severity %.4g, RMS change %.1f %% (< 10 %%), strongest effect line %.1f dB "
        "below the "
        "tenth peak (≥ 6 dB): %s\n",
        c.spec.effect.severity, 100.0 * c.concealment.rms_change, c.concealment.line_margin_db,
        c.concealed ? "CONCEALED" : "NOT CONCEALED");
  }
  const hal::Recording& rec = c.recording;
  if (const auto err = hal::write_bundle(out, rec)) {
    std::fprintf(stderr, "synth_lumped_bundle: %s\n", err->to_string().c_str());
    return 1;
  }
  std::ofstream(std::filesystem::path(out) / "truth.json")
      << tools::diagnosis::lumped_truth_json(c);
  std::printf("wrote %s: %zu samples at %.0f Hz, lumped gearbox, %s\n", out.c_str(),
              rec.sample_count(), fs,
              effect.empty() ? "no effect" : (effect + " at " + location).c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "synth_lumped_bundle: %s\n", e.what());
    return 1;
  }
}
