// synth_independent_bundle: a recording bundle (drivetwin-recording/1) of the reference
// gearbox made by the independent generator (independent_gearbox.hpp) — a model that is not
// the twin, with its own choices drawn from --seed — for calibration tests and demos.
//
//   synth_independent_bundle --out DIR [--rpm 8.33] [--torque 361747] [--duration 30]
//       [--seed 1] [--fs 25600] [--settle 1] [--no-tacho]
// Host tool: allocates; an exception ends it with its message and status 1.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <string>

#include "hal/recording_bundle.hpp"
#include "independent_gearbox.hpp"
#include "synth_independent_bundle_options.hpp"

namespace {
int run(int argc, char** argv) {
  CLI::App cli{"Recording bundle of paper-2mw from an independent lumped gearbox model"};
  tools::generator::SynthIndependentOptions o;
  tools::generator::add_options(cli, o, tools::options::operating_range(model::paper_2mw()));
  CLI11_PARSE(cli, argc, argv);
  const std::string& out = o.out;
  tools::generator::GeneratorSettings s = o.settings;
  const std::uint64_t seed = o.seed;
  const bool no_tacho = o.no_tacho;
  s.noise_seed = seed;

  const auto choices = tools::generator::GearboxChoices::draw(seed);
  const tools::generator::IndependentGearbox gearbox(choices);
  const tools::generator::GeneratedRecording r = gearbox.run(s);

  hal::Recording rec;
  rec.drivetrain = "paper-2mw";
  rec.sample_rate_hz = r.sample_rate_hz;
  rec.samples_file = "cms.wav";
  rec.channels = {{"point1", "b5", "radial", "", "m/s^2"}, {"point2", "b3", "radial", "", "m/s^2"}};
  rec.samples = {r.point1, r.point2};
  if (!no_tacho) {
    rec.channels.push_back({"tacho", "hss", "", "once_per_rev", "V"});
    rec.samples.push_back(r.tacho);
  }
  rec.operating_point.rotor_speed_rpm = r.mean_rotor_speed_rpm;
  rec.operating_point.input_torque_nm = r.mean_input_torque_nm;
  rec.notes = "independent generator (tools/gearbox_generator), seed " + std::to_string(seed) +
              ": " + choices.describe();
  if (const auto err = hal::write_bundle(out, rec)) {
    std::fprintf(stderr, "synth_independent_bundle: %s\n", err->to_string().c_str());
    return 1;
  }
  std::printf("wrote %s: %zu samples at %g Hz, mean %.4f rpm, %.0f N·m, seed %llu\n", out.c_str(),
              rec.sample_count(), r.sample_rate_hz, r.mean_rotor_speed_rpm, r.mean_input_torque_nm,
              static_cast<unsigned long long>(seed));
  return 0;
}
}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "synth_independent_bundle: %s\n", e.what());
    return 1;
  }
}
