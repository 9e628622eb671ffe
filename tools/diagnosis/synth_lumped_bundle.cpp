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
//       [--slip 0.01] [--damping-ratio 0.02] [--seed 1]
// Host tool: allocates and throws (caught here: message and status 1).
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <exception>
#include <numbers>
#include <random>
#include <string>

#include "concealment.hpp"
#include "hal/recording_bundle.hpp"
#include "lumped_gearbox.hpp"
#include "model/drivetrain/description.hpp"

namespace {

int run(int argc, char** argv) {
  CLI::App cli{"Recording bundle from the independent lumped gearbox model with one effect"};
  std::string out, effect, location;
  double severity = 0.0, rpm = 8.33, torque = 361747.0, duration = 30.0, fs = 25600.0, drift = 0.02,
         drift_period = 23.0, noise = 0.05, gain_error = 0.1, stiffness = 1.0, damping = 1.0, slip = 0.01,
         damping_ratio = 0.02;
  bool tacho = false;
  unsigned seed = 1;
  cli.add_option("--out", out, "Bundle directory to write")->required();
  cli.add_option("--effect", effect, "Effect id of the diagnosis contract (none when absent)");
  cli.add_option("--location", location, "Component id");
  cli.add_option("--severity", severity,
                 "crack: stiffness loss; eccentricity [m]; bearing: impact force [N]; unbalance [kg·m]; "
                 "misalignment [N]; planet pass: depth; resonance: frequency [Hz]");
  cli.add_option("--rpm", rpm, "Mean rotor speed [rpm]");
  cli.add_option("--torque", torque, "Rotor torque [N·m]");
  cli.add_option("--duration", duration, "Length [s]");
  cli.add_option("--fs", fs, "Sample rate [Hz]");
  cli.add_option("--drift", drift, "Relative amplitude of the slow speed drift");
  cli.add_option("--drift-period", drift_period, "Period of the speed drift [s]");
  cli.add_option("--noise", noise, "White noise RMS as a fraction of each channel's RMS");
  cli.add_option("--gain-error", gain_error, "Sensor gain error: each channel × (1 ± up to this)");
  cli.add_flag("--tacho", tacho, "Add a once-per-revolution tacho channel on the hss");
  cli.add_option("--stiffness-scale", stiffness, "Every mesh and bearing stiffness × this (parameter drift)");
  cli.add_option("--damping-scale", damping, "Damping × this (parameter drift)");
  cli.add_option("--slip", slip, "Bearing defects: rolling-element slip");
  cli.add_option("--damping-ratio", damping_ratio, "Housing resonance: damping ratio");
  cli.add_option("--seed", seed, "Noise, gain, jitter and drift-phase seed");
  CLI11_PARSE(cli, argc, argv);

  const model::Drivetrain d = model::paper_2mw();
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  const double phase = std::numbers::pi * uni(rng);
  const double f0 = rpm / 60.0;
  const double w = 2.0 * std::numbers::pi / drift_period;
  // Rotor angle with a slow speed drift: f(t) = f0·(1 + drift·sin(wt + φ)).
  auto revs = [=](double t) { return f0 * (t - drift / w * (std::cos(w * t + phase) - std::cos(phase))); };
  std::vector<tools::diagnosis::LumpedEffect> effects;
  if (!effect.empty()) effects.push_back({effect, location, severity, slip, damping_ratio});
  const double settle = 0.5;
  const auto with = tools::diagnosis::simulate_lumped(d, revs, torque, fs, duration, settle, effects, stiffness, damping, seed);
  auto wave = std::vector<std::vector<double>>{with.point1, with.point2};
  std::vector<std::vector<double>> clean = wave;
  for (std::size_t c = 0; c < wave.size(); ++c) {
    double mean = 0.0, ss = 0.0;
    for (double v : wave[c]) mean += v;
    mean /= static_cast<double>(wave[c].size());
    for (double v : wave[c]) ss += (v - mean) * (v - mean);
    std::normal_distribution<double> g(0.0, noise * std::sqrt(ss / static_cast<double>(wave[c].size())));
    const double gain = 1.0 + gain_error * uni(rng);
    for (double& v : wave[c]) v = gain * v + g(rng);
  }
  if (!effects.empty()) {
    const auto without = tools::diagnosis::simulate_lumped(d, revs, torque, fs, duration, settle, {}, stiffness, damping, seed);
    const auto c = tools::diagnosis::concealment(clean, {without.point1, without.point2}, wave);
    std::printf("concealment: RMS change %.1f %% (< 10 %%), strongest effect line %.1f dB below the tenth peak "
                "(≥ 6 dB): %s\n",
                100.0 * c.rms_change, c.line_margin_db, c.concealed() ? "CONCEALED" : "NOT CONCEALED");
  }
  hal::Recording rec;
  rec.drivetrain = "paper-2mw";
  rec.sample_rate_hz = fs;
  rec.channels = {{"point1", "b5", "radial", "", "m/s^2"}, {"point2", "b3", "radial", "", "m/s^2"}};
  rec.samples = std::move(wave);
  if (tacho) {
    std::vector<double> t(with.hss_revolutions.size());
    for (std::size_t i = 0; i < t.size(); ++i) {
      const double r = with.hss_revolutions[i];
      t[i] = r - std::floor(r) < 0.05 ? 5.0 : 0.0;
    }
    rec.channels.push_back({"tacho", "hss", "", "once_per_rev", "V"});
    rec.samples.push_back(std::move(t));
  }
  rec.operating_point.rotor_speed_rpm = rpm;
  rec.operating_point.input_torque_nm = torque;
  rec.notes = "lumped gearbox (tools/diagnosis): " + (effect.empty() ? std::string("no effect") : effect + " at " + location);
  if (const auto err = hal::write_bundle(out, rec)) {
    std::fprintf(stderr, "synth_lumped_bundle: %s\n", err->to_string().c_str());
    return 1;
  }
  std::printf("wrote %s: %zu samples at %.0f Hz, lumped gearbox, %s\n", out.c_str(), rec.sample_count(), fs,
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
