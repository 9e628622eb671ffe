// `drivetwin calibrate <bundle> [--json out]`: the paper's similarity
// indicators f1/f2/f3 of the twin's simulated vibration against a recording
// at both measurement points, and — when any is above its threshold — a
// calibration of the uncertain dynamics parameters (model/calibration/):
// --method trust-region (default; derivative-free least squares on the
// features, model/calibration/trust_region.hpp), improved or published MOGOA.
//
// Prints the indicators before, the optimiser's progress, the chosen
// parameters and the indicators after; --json writes the same with the keys
// of shared/reference/diagnosis-report.md (fit_before, fit_calibrated,
// residual_before, residual_calibrated) plus the parameters before and after.
//
// Exit status: 0 when every indicator ends within its threshold (or already
// was), 2 when the calibration could not bring them all within, 1 for a bad
// bundle or channel (a message names the file, the channel and what was wrong).
//
// Simulator: --simulator rom (default; the twin's dynamics ROM,
// model/dynamics/simulate.hpp, through model/calibration/dynamics_simulator.hpp)
// or lumped (model/calibration/lumped_simulator.hpp, the cheap stand-in the
// first calibrator was developed on); every output names it.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include "cli/command.hpp"
#include "config/drivetrain_file.hpp"
#include "hal/recording_bundle.hpp"
#include "model/calibration/calibrator.hpp"
#include "model/calibration/dynamics_simulator.hpp"
#include "model/calibration/lumped_simulator.hpp"
#include "model/drivetrain/kinematics.hpp"
#include "model/dsp/mesh_features.hpp"
#include "model/dsp/order_tracking.hpp"
#include "recording/bundle_check.hpp"
#include "signal/speed_reference.hpp"

namespace {

namespace mc = model::calibration;
namespace dsp = model::dsp;
namespace fs = std::filesystem;
using app::cli::CommandError;

// Residual band of diagnosis-report.md: order-tracked energy 0–5 kHz.
constexpr double kResidualBandHz = 5000.0;

struct CalibrateArgs {
  std::string bundle;
  std::string json;
  std::string drivetrain;  // overrides the bundle's drivetrain when set
  std::string method = "trust-region";
  std::string simulator = "rom";
  std::size_t evaluations = 60;
  std::size_t population = 20;
  std::size_t iterations = 50;
  std::uint64_t seed = 1;
  std::size_t samples_per_rev = 1024;
  std::size_t revolutions = 64;
  std::size_t harmonics = 3;
  bool force = false;
  bool quiet = false;
};

std::string describe(const hal::Recording& rec, const fs::path& dir, const std::string& channel) {
  return (dir / rec.samples_file).string() + ": channel '" + channel + "'";
}

// The recording's evidence for the speed reference (app/signal/speed_reference.hpp chooses):
// the hss tacho's pulses, the SCADA rotor speed, point 1 for the mesh line, the operating point.
app::signal::SpeedReference speed_reference(const hal::Recording& rec, const fs::path& dir,
                                            const model::Kinematics& k,
                                            const std::vector<double>& point1,
                                            dsp::FeatureExtractor& fx) {
  app::signal::SpeedEvidence e;
  e.min_pulses = fx.config().revolutions + 1;
  for (std::size_t c = 0; c < rec.channels.size() && e.hss_pulses_s.empty(); ++c) {
    const hal::BundleChannel& ch = rec.channels[c];
    if (ch.kind != "once_per_rev") continue;
    if (ch.location != "hss") {
      std::fprintf(stderr, "calibrate: note: tacho '%s' is on '%s', not the hss; not used\n",
                   ch.name.c_str(), ch.location.c_str());
      continue;
    }
    const std::size_t n = fx.tracker().detect_pulses(rec.samples[c].data(), rec.samples[c].size(),
                                                     rec.sample_rate_hz);
    if (n < e.min_pulses) {
      throw CommandError(describe(rec, dir, ch.name) + ": tacho gives " + std::to_string(n) +
                         " pulses; the order resolution needs " + std::to_string(e.min_pulses) +
                         " (a once-per-revolution pulse on the hss)");
    }
    e.hss_pulses_s.assign(fx.tracker().pulse_times(), fx.tracker().pulse_times() + n);
  }
  double sum = 0.0;
  std::size_t rows = 0;
  for (const hal::BundleScadaRow& r : rec.scada) {
    if (r.rotor_speed_rpm) {
      sum += *r.rotor_speed_rpm;
      ++rows;
    }
  }
  if (rows > 0) e.scada_rotor_rpm = sum / static_cast<double>(rows);
  e.point1 = point1.data();
  e.samples = point1.size();
  e.sample_rate_hz = rec.sample_rate_hz;
  e.nominal_rotor_rpm = rec.operating_point.rotor_speed_rpm;
  return app::signal::choose_speed_reference(e, k);
}

nlohmann::json fit_json(const mc::PointIndicators& ind) {
  nlohmann::json j;
  static constexpr const char* kNames[mc::kMeasurementPoints] = {"point1", "point2"};
  for (std::size_t p = 0; p < mc::kMeasurementPoints; ++p) {
    j[kNames[p]] = {{"f1", ind[p].f1},
                    {"f2", ind[p].f2},
                    {"f3", ind[p].f3},
                    {"tones", ind[p].tones},
                    {"valid", ind[p].valid}};
  }
  return j;
}

nlohmann::json params_json(const model::DynamicsParameters& p) {
  return {{"rayleigh_eta_1_s", p.rayleigh_eta},
          {"rayleigh_zeta_s", p.rayleigh_zeta},
          {"mesh_stiffness_scale", p.mesh_stiffness_scale},
          {"bearing_stiffness_scale", p.bearing_stiffness_scale}};
}

void print_fit(const char* title, const mc::PointIndicators& ind) {
  std::printf("%s\n  point   f1 (<=0.5)  f2 (<=0.2)  f3 (<=0.2)  tones\n", title);
  static constexpr const char* kNames[mc::kMeasurementPoints] = {"point1", "point2"};
  for (std::size_t p = 0; p < mc::kMeasurementPoints; ++p) {
    std::printf("  %-6s  %9.4f%s  %9.4f%s  %9.4f%s  %5zu%s\n", kNames[p], ind[p].f1,
                ind[p].f1 > mc::kF1Threshold ? "*" : " ", ind[p].f2,
                ind[p].f2 > mc::kF2Threshold ? "*" : " ", ind[p].f3,
                ind[p].f3 > mc::kF3Threshold ? "*" : " ", ind[p].tones,
                ind[p].valid ? "" : "  (invalid)");
  }
}

void print_params(const char* title, const model::DynamicsParameters& p) {
  std::printf(
      "%s eta %.4g 1/s, zeta %.4g s, mesh scale %.3f %.3f %.3f, bearing scale %.3f %.3f %.3f\n",
      title, p.rayleigh_eta, p.rayleigh_zeta, p.mesh_stiffness_scale[0], p.mesh_stiffness_scale[1],
      p.mesh_stiffness_scale[2], p.bearing_stiffness_scale[0], p.bearing_stiffness_scale[1],
      p.bearing_stiffness_scale[2]);
}

// Share of the measured order-spectrum energy (0–5 kHz, both points) the
// simulation does not explain: Σ(a_m − a_s)² / Σ a_m², clipped to [0, 1].
double residual(const std::array<std::vector<double>, mc::kMeasurementPoints>& measured,
                const std::array<std::vector<double>, mc::kMeasurementPoints>& simulated,
                std::size_t last_line) {
  double miss = 0.0;
  double total = 0.0;
  for (std::size_t p = 0; p < mc::kMeasurementPoints; ++p) {
    for (std::size_t k = 1; k <= last_line && k < measured[p].size(); ++k) {
      const double d = measured[p][k] - simulated[p][k];
      miss += d * d;
      total += measured[p][k] * measured[p][k];
    }
  }
  return total > 0.0 ? std::clamp(miss / total, 0.0, 1.0) : 1.0;
}

void run(const CalibrateArgs& args) {
  const fs::path dir(args.bundle);
  // The bundle validation layer (app/recording/bundle_check.hpp): format, units, the
  // turbine's range, metadata against the signal, torque from the wind when not recorded.
  app::recording::CheckedBundle bundle;
  try {
    bundle = app::recording::load_bundle(dir, {args.drivetrain});
  } catch (const app::recording::BundleCheckError& e) {
    throw CommandError(e.what());
  }
  for (const auto& note : bundle.notes) std::fprintf(stderr, "calibrate: note: %s\n", note.c_str());
  const hal::Recording& rec = bundle.recording;
  const model::Drivetrain& drivetrain = bundle.drivetrain;
  const model::Kinematics kinematics(drivetrain);

  // Measurement channels, by the description's measurement points.
  std::array<const std::vector<double>*, mc::kMeasurementPoints> wave{};
  std::array<std::string, mc::kMeasurementPoints> channel{};
  for (std::size_t p = 0; p < mc::kMeasurementPoints; ++p) {
    if (p >= drivetrain.measurement_points.size()) {
      throw CommandError("drivetrain '" + drivetrain.name +
                         "': measurement_points: calibration needs 2, found " +
                         std::to_string(drivetrain.measurement_points.size()));
    }
    channel[p] = drivetrain.measurement_points[p].channel;
    const auto idx = rec.channel_index(channel[p]);
    if (!idx) {
      throw CommandError((dir / "recording.json").string() + ": channels: no channel named '" +
                         channel[p] + "' (measurement point at " +
                         drivetrain.measurement_points[p].location + ")");
    }
    wave[p] = &rec.samples[*idx];
  }

  // Simulator and calibrator (the calibrator fills the mesh orders).
  dsp::FeatureConfig fc;
  fc.samples_per_rev = args.samples_per_rev;
  fc.revolutions = args.revolutions;
  fc.harmonics = args.harmonics;
  mc::CalibratorConfig cc;
  if (args.method == "published") {
    cc.method = mc::CalibrationMethod::kPublishedMogoa;
  } else if (args.method == "improved") {
    cc.method = mc::CalibrationMethod::kImprovedMogoa;
  } else if (args.method == "trust-region") {
    cc.method = mc::CalibrationMethod::kTrustRegion;
  } else {
    throw CommandError("--method: expected 'trust-region', 'improved' or 'published', got '" +
                       args.method + "'");
  }
  cc.mogoa.population = args.population;
  cc.mogoa.max_iterations = args.iterations;
  cc.mogoa.seed = args.seed;
  cc.trust_region.max_evaluations = args.evaluations;
  cc.trust_region.seed = args.seed == 1 ? 0 : args.seed;  // seed 1 (default): probes along the axes
  mc::LumpedSimulatorConfig sc;
  sc.harmonics = args.harmonics;
  sc.max_duration_s =
      4.0 * static_cast<double>(args.revolutions + 4) /
      (std::max(rec.operating_point.rotor_speed_rpm, 1e-3) / 60.0 * kinematics.overall_ratio());
  // Simulated waveform rate: ≥ 4× the highest mesh harmonic.
  const double top_hz =
      kinematics.mesh_hz(kinematics.stage_count() - 1, rec.operating_point.rotor_speed_rpm) *
      static_cast<double>(args.harmonics);
  sc.sample_rate_hz = std::max(4096.0, std::exp2(std::ceil(std::log2(4.0 * top_hz))));
  std::unique_ptr<mc::VibrationSimulator> simulator;
  if (args.simulator == "lumped") {
    simulator = std::make_unique<mc::LumpedSimulator>(drivetrain, sc);
  } else if (args.simulator == "rom") {
    // The ROM at the recording's rate would cost most: ≥ 6× the top harmonic
    // (dynamics_simulator.hpp), after 0.5 s of settling from the static deflection.
    simulator = std::make_unique<mc::DynamicsSimulator>(drivetrain, mc::DynamicsModel::kRom,
                                                        mc::rom_sample_rate_hz(top_hz), 0.5);
  } else {
    throw CommandError("--simulator: expected 'rom' or 'lumped', got '" + args.simulator + "'");
  }
  auto calibrator = std::make_unique<mc::Calibrator>(*simulator, drivetrain, fc, cc);
  if (calibrator->status() != dsp::DspStatus::kOk) {
    throw CommandError("--revolutions/--samples-per-rev/--harmonics: " +
                       std::string(dsp::to_string(calibrator->status())));
  }
  dsp::FeatureExtractor fx(calibrator->feature_config());

  // Channel quality before anything is computed from it.
  for (std::size_t p = 0; p < mc::kMeasurementPoints; ++p) {
    const dsp::DspStatus q =
        dsp::check_waveform(wave[p]->data(), wave[p]->size(), fx.config().flat_threshold);
    if (q != dsp::DspStatus::kOk)
      throw CommandError(describe(rec, dir, channel[p]) + ": " + dsp::to_string(q));
  }
  const app::signal::SpeedReference speed = speed_reference(rec, dir, kinematics, *wave[0], fx);
  const dsp::SpeedReference ref{speed.pulses.empty() ? nullptr : speed.pulses.data(),
                                speed.pulses.size(), speed.hss_hz};
  const double hss_hz = speed.mean_hss_hz();

  std::array<dsp::PointFeatures, mc::kMeasurementPoints> measured{};
  std::array<std::vector<double>, mc::kMeasurementPoints> measured_spectrum;
  for (std::size_t p = 0; p < mc::kMeasurementPoints; ++p) {
    const dsp::DspStatus s =
        fx.extract(wave[p]->data(), wave[p]->size(), rec.sample_rate_hz, ref, measured[p]);
    if (s == dsp::DspStatus::kTooShort) {
      char text[160];
      std::snprintf(text, sizeof text,
                    ": recording of %.2f s is too short: %zu hss revolutions (order resolution "
                    "1/%zu) need %.2f s",
                    static_cast<double>(wave[p]->size()) / rec.sample_rate_hz,
                    fx.config().revolutions, fx.config().revolutions,
                    fx.required_duration_s(hss_hz));
      throw CommandError(describe(rec, dir, channel[p]) + text);
    }
    if (s != dsp::DspStatus::kOk)
      throw CommandError(describe(rec, dir, channel[p]) + ": " + dsp::to_string(s));
    measured_spectrum[p].assign(
        fx.order_spectrum(),
        fx.order_spectrum() + (fx.config().samples_per_rev * fx.config().revolutions / 2 + 1));
    if (measured[p].resolved_count() < mc::kMinTones) {
      throw CommandError(describe(rec, dir, channel[p]) + ": only " +
                         std::to_string(measured[p].resolved_count()) + " of " +
                         std::to_string(measured[p].count) +
                         " mesh harmonics stand out of the noise; f2/f3 need at least " +
                         std::to_string(mc::kMinTones));
    }
  }

  mc::OperatingPoint op{rec.operating_point.rotor_speed_rpm, 0.0};
  // Mean rotor speed from the speed reference; torque as recorded, else from the wind.
  op.rotor_speed_rpm = hss_hz / kinematics.overall_ratio() * 60.0;
  op.input_torque_nm = bundle.input_torque_nm;  // recorded, or the wind model's (noted above)
  calibrator->set_measurement(measured, op);

  const model::DynamicsParameters before = mc::with_nominal_damping(drivetrain.dynamics);
  if (before.rayleigh_eta != drivetrain.dynamics.rayleigh_eta) {
    std::fprintf(stderr,
                 "calibrate: note: drivetrain '%s' has no damping; starting from eta %.3g 1/s, "
                 "zeta %.3g s\n",
                 drivetrain.name.c_str(), before.rayleigh_eta, before.rayleigh_zeta);
  }

  // Spectra of a parameter set, for the residual.
  const std::size_t last_line = static_cast<std::size_t>(
      kResidualBandHz / hss_hz * static_cast<double>(fx.config().revolutions));
  auto simulated_spectra = [&](const model::DynamicsParameters& params) {
    std::array<std::vector<double>, mc::kMeasurementPoints> out;
    std::array<mc::WaveformView, mc::kMeasurementPoints> w{};
    const double ref_hz = hss_hz;
    if (!simulator->simulate(params, op, fx.required_duration_s(ref_hz) + 1.0 / ref_hz, w))
      return out;
    for (std::size_t p = 0; p < mc::kMeasurementPoints; ++p) {
      dsp::PointFeatures unused;
      if (fx.extract(w[p].samples, w[p].count, w[p].sample_rate_hz, {nullptr, 0, ref_hz}, unused) ==
          dsp::DspStatus::kOk) {
        out[p].assign(fx.order_spectrum(), fx.order_spectrum() + measured_spectrum[p].size());
      } else {
        out[p].assign(measured_spectrum[p].size(), 0.0);
      }
    }
    return out;
  };

  mc::PointIndicators fit_before{};
  if (!calibrator->evaluate(before, fit_before))
    throw CommandError("simulation failed at the starting parameters");
  const double residual_before = residual(measured_spectrum, simulated_spectra(before), last_line);

  if (!args.quiet) {
    std::printf("bundle %s: %s, rotor %.3f rpm (speed from %s), torque %.0f N·m\n",
                dir.string().c_str(), drivetrain.name.c_str(), op.rotor_speed_rpm,
                speed.source.c_str(), op.input_torque_nm);
    std::printf("simulator: %s\n",
                args.simulator == "rom"
                    ? "dynamics ROM (model/dynamics, simulate_rom)"
                    : "lumped stand-in (3 shafts, mesh transmission error; not the dynamics ROM)");
    print_params("parameters before:", before);
    print_fit("fit before:", fit_before);
    std::printf("residual before: %.3f\n", residual_before);
  }

  mc::CalibrationResult result;
  result.parameters = before;
  result.indicators = fit_before;
  result.fits = !mc::needs_calibration(fit_before);
  const bool run_optimizer = args.force || mc::needs_calibration(fit_before);
  double seconds = 0.0;
  if (!run_optimizer) {
    if (!args.quiet) std::printf("every indicator within its threshold: no calibration needed\n");
  } else {
    if (!args.quiet) {
      if (cc.method == mc::CalibrationMethod::kTrustRegion) {
        std::printf(
            "calibrating: trust-region least squares on the features, at most %zu evaluations\n",
            args.evaluations);
      } else {
        std::printf("calibrating: %s MOGOA, %zu grasshoppers x %zu iterations, seed %llu\n",
                    args.method.c_str(), args.population, args.iterations,
                    static_cast<unsigned long long>(args.seed));
      }
    }
    const auto t0 = std::chrono::steady_clock::now();
    calibrator->start(before);
    mc::StepStatus st;
    while ((st = calibrator->step()) == mc::StepStatus::kRunning) {
      const bool tr = cc.method == mc::CalibrationMethod::kTrustRegion;
      if (!args.quiet && tr) {
        std::printf("  evaluation %3zu  best worst-indicator/threshold %.3f  trust radius %.3g%s\n",
                    calibrator->evaluations(), calibrator->best_ratio(), calibrator->trust_radius(),
                    calibrator->evaluations_to_threshold() ? "  (fit found)" : "");
      } else if (!args.quiet &&
                 (calibrator->iteration() % 5 == 0 || calibrator->iteration() <= 1)) {
        std::printf("  iteration %3zu  evaluations %5zu  best worst-indicator/threshold %.3f%s\n",
                    calibrator->iteration(), calibrator->evaluations(), calibrator->best_ratio(),
                    calibrator->evaluations_to_threshold() ? "  (fit found)" : "");
      }
    }
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!calibrator->read_result(result)) throw CommandError("calibration published no result");
    if (!args.quiet) {
      std::printf("done: %zu evaluations in %.1f s; first fitting evaluation: %zu\n",
                  result.evaluations, seconds, result.evaluations_to_threshold);
    }
  }
  const double residual_after =
      residual(measured_spectrum, simulated_spectra(result.parameters), last_line);
  if (!args.quiet) {
    print_params("parameters calibrated:", result.parameters);
    print_fit("fit calibrated:", result.indicators);
    std::printf("residual calibrated: %.3f\n", residual_after);
    std::printf("%s\n",
                result.fits
                    ? "CALIBRATED: every indicator within its threshold at both points"
                    : "NOT CALIBRATED: some indicator remains above its threshold (marked *)");
  }

  if (!args.json.empty()) {
    nlohmann::json j;
    j["format"] = "drivetwin-calibration/1";
    j["bundle"] = dir.filename().string().empty() ? dir.parent_path().filename().string()
                                                  : dir.filename().string();
    j["operating_point"] = {{"rotor_speed_rpm", op.rotor_speed_rpm},
                            {"input_torque_nm", op.input_torque_nm}};
    j["speed_source"] = speed.source;
    j["simulator"] = args.simulator == "rom" ? "dynamics-rom" : "lumped-stand-in";
    j["method"] = args.method;
    j["fit_before"] = fit_json(fit_before);
    j["fit_calibrated"] = fit_json(result.indicators);
    j["residual_before"] = residual_before;
    j["residual_calibrated"] = residual_after;
    j["parameters_before"] = params_json(before);
    j["parameters_calibrated"] = params_json(result.parameters);
    j["calibration_ran"] = run_optimizer;
    j["fits"] = result.fits;
    j["evaluations"] = result.evaluations;
    j["evaluations_to_threshold"] = result.evaluations_to_threshold;
    j["seconds"] = seconds;
    std::ofstream out(args.json);
    out << j.dump(2) << "\n";
    if (!out) throw CommandError(args.json + ": cannot write");
  }
  if (!result.fits) app::cli::exit_status() = 2;
}

void setup_calibrate(CLI::App& sub) {
  auto args = std::make_shared<CalibrateArgs>();
  sub.add_option("bundle", args->bundle, "Recording bundle directory (drivetwin-recording/1)")
      ->required();
  sub.add_option("--json", args->json, "Write the result as JSON to this file");
  sub.add_option("--drivetrain", args->drivetrain, "Drivetrain NAME|FILE (default: the bundle's)");
  sub.add_option("--method", args->method, "trust-region (default), improved or published MOGOA");
  sub.add_option("--simulator", args->simulator,
                 "rom (default, the dynamics ROM) or lumped (stand-in)");
  sub.add_option("--evaluations", args->evaluations,
                 "trust-region: model evaluations at most (default 60)");
  sub.add_option("--population", args->population, "Grasshoppers (default 20)");
  sub.add_option("--iterations", args->iterations, "MOGOA iterations (default 50)");
  sub.add_option(
      "--seed", args->seed,
      "Random seed (default 1; trust region: 1 probes along the axes, others a random basis)");
  sub.add_option("--revolutions", args->revolutions,
                 "hss revolutions per analysis block (default 64)");
  sub.add_option("--samples-per-rev", args->samples_per_rev,
                 "Angle-domain samples per hss revolution (default 1024)");
  sub.add_option("--harmonics", args->harmonics,
                 "Mesh harmonics compared, fundamental included (default 3)");
  sub.add_flag("--force", args->force,
               "Calibrate even when every indicator is within its threshold");
  sub.add_flag("--quiet", args->quiet, "Print nothing but errors");
  sub.callback([args] { run(*args); });
}

const bool kCalibrateRegistered = app::cli::register_command(
    {"calibrate",
     "Similarity indicators f1/f2/f3 against a recording; MOGOA calibration when above threshold",
     &setup_calibrate});

}  // namespace
