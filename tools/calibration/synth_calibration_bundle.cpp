// synth_calibration_bundle: writes a recording bundle (drivetwin-recording/1)
// whose point1/point2 waveforms are simulated with parameters off nominal,
// plus white noise — the recordings of the Table 3 demonstration (README,
// "Calibration"). The "measured" vibration comes from the FULL-order dynamics
// model (model/dynamics/full_model.hpp, Newmark, 140 DOF) by default, while
// `drivetwin calibrate` calibrates the ROM: truth and calibration model differ
// (no inverse crime). --model rom or lumped (the stand-in) are selectable.
// Host tool: allocates and throws.
//
//   synth_calibration_bundle --out DIR [--rpm 8.33] [--torque 361747]
//       [--damping-factor 2] [--mesh-scale 0.8] [--bearing-scale 1.3]
//       [--noise 0.05] [--duration 6] [--fs 25600] [--tacho] [--seed 1]
//       [--model full|rom|lumped] [--settle 0.5]
//       [--fault flat:point2|clip:point1|drop:point2]   (bad-input fixtures)
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <memory>
#include <random>
#include <string>

#include "hal/recording_bundle.hpp"
#include "model/calibration/dynamics_simulator.hpp"
#include "model/calibration/lumped_simulator.hpp"
#include "model/drivetrain/kinematics.hpp"
#include "synth_calibration_bundle_options.hpp"

namespace {
int run(int argc, char** argv) {
  CLI::App cli{"Simulated off-nominal recording bundle for the calibration demo"};
  tools::calibration::SynthCalibrationOptions o;
  tools::calibration::add_options(cli, o, tools::options::operating_range(model::paper_2mw()));
  CLI11_PARSE(cli, argc, argv);
  const std::string& out = o.out;
  const double rpm = o.rpm, torque = o.torque, damping_factor = o.damping_factor;
  const double mesh_scale = o.mesh_scale, bearing_scale = o.bearing_scale, noise = o.noise;
  const double duration_s = o.duration_s, fs_hz = o.fs_hz, settle_s = o.settle_s;
  const bool tacho = o.tacho;
  const std::uint64_t seed = o.seed;
  const std::string& fault = o.fault;
  const std::string& model_name = o.model_name;

  const model::Drivetrain drivetrain = model::paper_2mw();
  model::DynamicsParameters truth = model::calibration::with_nominal_damping(drivetrain.dynamics);
  truth.rayleigh_eta *= damping_factor;
  truth.rayleigh_zeta *= damping_factor;
  truth.mesh_stiffness_scale = {mesh_scale, mesh_scale, mesh_scale};
  truth.bearing_stiffness_scale = {bearing_scale, bearing_scale, bearing_scale};

  namespace mc = model::calibration;
  std::unique_ptr<mc::VibrationSimulator> sim;
  mc::DynamicsSimulator* dynamics = nullptr;
  if (model_name == "lumped") {
    mc::LumpedSimulatorConfig sc;
    sc.sample_rate_hz = fs_hz;
    sc.max_duration_s = duration_s;
    sc.noise_relative = noise;
    sc.noise_seed = seed;
    sim = std::make_unique<mc::LumpedSimulator>(drivetrain, sc);
  } else {
    auto d = std::make_unique<mc::DynamicsSimulator>(
        drivetrain, model_name == "full" ? mc::DynamicsModel::kFull : mc::DynamicsModel::kRom,
        fs_hz, settle_s);
    dynamics = d.get();
    sim = std::move(d);
  }
  std::array<mc::WaveformView, mc::kMeasurementPoints> w{};
  if (!sim->simulate(truth, {rpm, torque}, duration_s, w)) {
    std::fprintf(stderr,
                 "synth_calibration_bundle: simulation failed (rpm %g, duration %g s)%s%s\n", rpm,
                 duration_s, dynamics ? ": " : "", dynamics ? dynamics->error().c_str() : "");
    return 1;
  }
  std::array<std::vector<double>, mc::kMeasurementPoints> wave;
  for (std::size_t p = 0; p < mc::kMeasurementPoints; ++p)
    wave[p].assign(w[p].samples, w[p].samples + w[p].count);
  if (dynamics && noise > 0.0) {
    // White Gaussian noise, RMS = noise × the channel's RMS (mean removed); the stand-in adds its
    // own.
    std::mt19937_64 rng(seed);
    for (auto& x : wave) {
      double mean = 0.0;
      for (double v : x) mean += v;
      mean /= static_cast<double>(x.size());
      double ss = 0.0;
      for (double v : x) ss += (v - mean) * (v - mean);
      std::normal_distribution<double> gauss(0.0,
                                             noise * std::sqrt(ss / static_cast<double>(x.size())));
      for (double& v : x) v += gauss(rng);
    }
  }

  hal::Recording rec;
  rec.drivetrain = "paper-2mw";
  rec.sample_rate_hz = fs_hz;
  rec.samples_file = "cms.wav";
  rec.channels = {{"point1", "b5", "radial", "", "m/s^2"}, {"point2", "b3", "radial", "", "m/s^2"}};
  rec.samples = {wave[0], wave[1]};
  if (tacho) {
    const double hss_hz = rpm / 60.0 * model::Kinematics(drivetrain).overall_ratio();
    std::vector<double> t(w[0].count);
    for (std::size_t i = 0; i < t.size(); ++i) {
      // The dynamics models report their hss angle; the stand-in's starts at 0.
      const double rev =
          dynamics ? dynamics->hss_revolutions()[i] : hss_hz * static_cast<double>(i) / fs_hz;
      t[i] = rev - std::floor(rev) < 0.05 ? 5.0 : 0.0;  // 5 V pulse over 5 % of a revolution
    }
    rec.channels.push_back({"tacho", "hss", "", "once_per_rev", "V"});
    rec.samples.push_back(std::move(t));
  }
  if (!fault.empty()) {
    const auto colon = fault.find(':');
    const std::string kind = fault.substr(0, colon);
    const std::string name = colon == std::string::npos ? "" : fault.substr(colon + 1);
    const auto idx = rec.channel_index(name);
    if (!idx || (kind != "flat" && kind != "clip" && kind != "drop")) {
      std::fprintf(
          stderr,
          "synth_calibration_bundle: --fault: expected flat|clip|drop:<channel>, got '%s'\n",
          fault.c_str());
      return 1;
    }
    std::vector<double>& x = rec.samples[*idx];
    if (kind == "flat") std::fill(x.begin(), x.end(), 0.0);
    if (kind == "clip") {
      double peak = 0.0;
      for (double v : x) peak = std::max(peak, std::abs(v));
      for (double& v : x) v = std::clamp(v, -0.6 * peak, 0.6 * peak);
    }
    if (kind == "drop") {
      rec.channels.erase(rec.channels.begin() + static_cast<long>(*idx));
      rec.samples.erase(rec.samples.begin() + static_cast<long>(*idx));
    }
  }
  rec.operating_point.rotor_speed_rpm = rpm;
  rec.operating_point.input_torque_nm = torque;
  char notes[256];
  std::snprintf(
      notes, sizeof notes,
      "synthetic (%s model): damping x%g (eta %g 1/s, zeta %g s), mesh stiffness x%g, bearing "
      "stiffness x%g, noise %g of RMS, seed %llu",
      model_name == "lumped" ? "lumped stand-in"
      : model_name == "full" ? "full-order dynamics"
                             : "dynamics ROM",
      damping_factor, truth.rayleigh_eta, truth.rayleigh_zeta, mesh_scale, bearing_scale, noise,
      static_cast<unsigned long long>(seed));
  rec.notes = notes;
  if (const auto err = hal::write_bundle(out, rec)) {
    std::fprintf(stderr, "synth_calibration_bundle: %s\n", err->to_string().c_str());
    return 1;
  }
  std::printf("wrote %s: %zu samples at %g Hz, %s\n", out.c_str(), rec.sample_count(), fs_hz,
              notes);
  return 0;
}
}  // namespace

// Anything thrown (a file that cannot be written, a model that cannot be built) ends the tool with
// its message and exit status 1, never with std::terminate.
int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "synth_calibration_bundle: %s\n", e.what());
    return 1;
  }
}
