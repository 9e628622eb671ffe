// `drivetwin calibrate <bundle> [<bundle> ...] [--json out] [--update FILE]`: the paper's
// similarity indicators f1/f2/f3 of the twin's simulated vibration against recordings at both
// measurement points, and — when any is above its threshold — a calibration of the dynamics
// parameters (model/calibration/; docs/calibration.md):
//  - the space: --space standard (damping with band factors, mesh and per-bearing
//    stiffness, each stage's transmission error, three housing modes per point; priors from
//    the drivetrain description), seats, body (standard + the gearbox body on its mounts),
//    paper (the paper's 8 variables) or auto (the default with the ROM: standard, and
//    standard + body from the same start only when standard does not calibrate; the result
//    kept by mc::choose_space and named under "model_selection" in the JSON);
//  - --method trust-region (default: the variables the recordings can determine are
//    identified from the feature Jacobian, then fitted by Gauss–Newton with the prior,
//    model/calibration/calibrator.hpp), improved or published MOGOA;
//  - several bundles (operating points) calibrate one parameter set jointly; each bundle's
//    features are averaged over --windows analysis blocks of it.
//
// Prints the indicators before, the progress, every variable (prior, value, posterior σ ratio,
// identified / not identified / at a bound) and the indicators after; --json writes the same
// with the keys of shared/reference/diagnosis-report.md (fit_before, fit_calibrated,
// residual_before, residual_calibrated; the first bundle's at the top, every bundle's under
// "cases"). --update FILE writes the calibrated parameters into a drivetrain description
// (FILE's own when it exists, else the one calibrated), only when the result is CALIBRATED.
//
// Exit status: 0 when every indicator ends within its threshold (or already was) and no
// fitted variable ends at a bound, 2 otherwise (NOT CALIBRATED, naming why), 1 for a bad
// bundle, channel or option (a message names the file, the channel and what was wrong).
//
// Simulator: --simulator rom (default; the twin's dynamics ROM at the recording's sample
// rate, model/dynamics/simulate.hpp, through model/calibration/dynamics_simulator.hpp)
// or lumped (model/calibration/lumped_simulator.hpp, the first calibrator's stand-in).
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include "cli/command.hpp"
#include "cli/options.hpp"
#include "config/drivetrain_file.hpp"
#include "hal/recording_bundle.hpp"
#include "model/calibration/calibrator.hpp"
#include "model/calibration/dynamics_simulator.hpp"
#include "model/calibration/lumped_simulator.hpp"
#include "model/calibration/resonance_placement.hpp"
#include "model/drivetrain/kinematics.hpp"
#include "model/dsp/mesh_features.hpp"
#include "model/dsp/spectrum.hpp"
#include "recording/bundle_check.hpp"
#include "recording/calibration_measurement.hpp"

namespace {

namespace mc = model::calibration;
namespace dsp = model::dsp;
namespace fs = std::filesystem;
using app::cli::CommandError;

using app::recording::kCalibrateResidualBandHz;
using MeasuredBundle = app::recording::CalibrationMeasurement;

struct CalibrateArgs {
  std::vector<std::string> bundles;
  std::string json;
  std::string update;
  std::string drivetrain;  // overrides the bundles' drivetrain when set
  std::string method = "trust-region";
  std::string simulator = "rom";
  std::string space;  // "": standard with the ROM, paper with the lumped stand-in
  std::size_t evaluations = mc::kDefaultFitEvaluations;
  std::size_t population = 20;
  std::size_t iterations = 50;
  std::uint64_t seed = 1;
  std::size_t samples_per_rev = 1024;
  std::size_t revolutions = 64;
  std::size_t harmonics = 3;
  std::size_t windows = 4;
  double residual_sd = app::recording::kCalibrateResidualSd;
  bool force = false;
  bool quiet = false;
  bool probe_every_round = false;
};

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

nlohmann::json variables_json(const mc::CalibrationSpace& space, const mc::CalibrationResult& r,
                              bool ran) {
  nlohmann::json list = nlohmann::json::array();
  for (std::size_t i = 0; i < space.size(); ++i) {
    const mc::CalibrationVariable& v = space.variable(i);
    nlohmann::json j = {{"name", space.name(i)},
                        {"unit", v.unit.data()},
                        {"prior", mc::CalibrationSpace::get(space.prior(), v)},
                        {"prior_sd", v.prior_sd},
                        {"scale", v.logarithmic ? "log" : "linear"},
                        {"lower", v.lower},
                        {"upper", v.upper},
                        {"value", mc::CalibrationSpace::get(r.parameters, v)}};
    if (ran) {
      j["status"] = mc::to_string(r.status[i]);
      j["posterior_sd_ratio"] = r.posterior_ratio[i];
      j["z"] = r.z[i];
    } else {
      j["status"] = "not calibrated";
    }
    list.push_back(j);
  }
  return list;
}

nlohmann::json params_json(const model::DynamicsParameters& p) {
  return {{"rayleigh_eta_1_s", p.rayleigh_eta},
          {"rayleigh_zeta_s", p.rayleigh_zeta},
          {"mesh_stiffness_scale", p.mesh_stiffness_scale},
          {"mesh_tip_relief", p.mesh_tip_relief},
          {"bearing_stiffness_scale", p.bearing_stiffness_scale},
          {"bearing_stiffness_factor", p.bearing_stiffness_factor},
          {"sun_shaft_torsion_scale", p.sun_shaft_torsion_scale},
          {"bearing_compliance_scale", p.bearing_compliance_scale},
          {"bearing_stiffness_fluctuation", p.bearing_stiffness_fluctuation},
          {"damping_band_factor", p.damping_band_factor},
          {"transmission_error_m", p.transmission_error_m},
          {"transmission_error_phase_rad", p.transmission_error_phase_rad},
          {"housing_frequency_hz", p.housing_frequency_hz},
          {"housing_damping_ratio", p.housing_damping_ratio},
          {"housing_modal_mass_kg", p.housing_modal_mass_kg},
          {"housing_participation", p.housing_participation},
          {"housing_cross_participation", p.housing_cross_participation},
          {"housing_seat_participation", p.housing_seat_participation},
          {"gearbox_body_mass_kg", p.gearbox_body_mass_kg},
          {"gearbox_mount_stiffness_n_m", p.gearbox_mount_stiffness_n_m},
          {"gearbox_mount_damping_ratio", p.gearbox_mount_damping_ratio}};
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

void print_variables(const mc::CalibrationSpace& space, const mc::CalibrationResult& r) {
  std::printf("  %-46s %11s %11s %6s  %s\n", "variable", "prior", "value", "sd/pr", "status");
  for (std::size_t i = 0; i < space.size(); ++i) {
    const mc::CalibrationVariable& v = space.variable(i);
    std::printf("  %-46s %11.4g %11.4g %6.2f  %s\n",
                (std::string(space.name(i)) + " [" + v.unit.data() + "]").c_str(),
                mc::CalibrationSpace::get(space.prior(), v),
                mc::CalibrationSpace::get(r.parameters, v), r.posterior_ratio[i],
                mc::to_string(r.status[i]));
  }
}

// One compared mesh tone of one point, measured and simulated before and after.
struct ToneRow {
  std::size_t point = 0;
  std::size_t stage = 0;     // 0: planetary, 1: intermediate, 2: high-speed
  std::size_t harmonic = 1;  // of the mesh frequency
  double order = 0.0;        // [hss orders]
  double measured = 0.0;     // [m/s²] averaged over the windows
  double floor = 0.0;        // [m/s²] what noise alone reads
  bool resolved = false;     // compared (above the noise, separable)
  double before = 0.0;       // [m/s²] simulated at the prior
  double after = 0.0;        // [m/s²] simulated at the calibrated parameters
};

const char* stage_name(std::size_t stage) {
  static constexpr const char* kNames[] = {"planetary", "intermediate", "high-speed"};
  return stage < 3 ? kNames[stage] : "stage";
}

// The tones of each point, strongest measured first, with the rank of each after calibration.
void print_tones(const std::vector<ToneRow>& rows) {
  static constexpr const char* kNames[mc::kMeasurementPoints] = {"point1", "point2"};
  for (std::size_t p = 0; p < mc::kMeasurementPoints; ++p) {
    std::vector<const ToneRow*> mine;
    for (const ToneRow& r : rows)
      if (r.point == p) mine.push_back(&r);
    std::vector<const ToneRow*> by_after = mine;
    std::stable_sort(mine.begin(), mine.end(),
                     [](const ToneRow* a, const ToneRow* b) { return a->measured > b->measured; });
    std::stable_sort(by_after.begin(), by_after.end(),
                     [](const ToneRow* a, const ToneRow* b) { return a->after > b->after; });
    std::printf(
        "  %s mesh tones [m/s²], strongest measured first (rank after calibration):\n"
        "    %-16s %7s %10s %10s %10s %10s  %s\n",
        kNames[p], "mesh", "order", "measured", "floor", "before", "after", "");
    for (const ToneRow* r : mine) {
      const auto rank = static_cast<std::size_t>(std::find(by_after.begin(), by_after.end(), r) -
                                                 by_after.begin() + 1);
      char mesh[32];
      std::snprintf(mesh, sizeof mesh, "%s %zux", stage_name(r->stage), r->harmonic);
      std::printf("    %-16s %7.3f %10.4g %10.4g %10.4g %10.4g  #%zu%s\n", mesh, r->order,
                  r->measured, r->floor, r->before, r->after, rank,
                  r->resolved ? "" : "  (not compared: below the noise or not separable)");
    }
  }
}

nlohmann::json tones_json(const std::vector<ToneRow>& rows) {
  static constexpr const char* kNames[mc::kMeasurementPoints] = {"point1", "point2"};
  nlohmann::json list = nlohmann::json::array();
  for (const ToneRow& r : rows) {
    list.push_back({{"point", kNames[r.point]},
                    {"stage", stage_name(r.stage)},
                    {"harmonic", r.harmonic},
                    {"order", r.order},
                    {"measured", r.measured},
                    {"noise_floor", r.floor},
                    {"compared", r.resolved},
                    {"simulated_before", r.before},
                    {"simulated_after", r.after}});
  }
  return list;
}

// Share of the measured order-spectrum energy (0–5 kHz, both points) the simulation does
// not explain, Σ(a_m − a_s)² / Σ a_m², before any clip: > 1 when the twin adds more energy
// than it explains (lines the recording lacks).
double residual_unclipped(const std::array<std::vector<double>, mc::kMeasurementPoints>& measured,
                          const std::array<std::vector<double>, mc::kMeasurementPoints>& simulated,
                          std::size_t last_line) {
  double miss = 0.0;
  double total = 0.0;
  for (std::size_t p = 0; p < mc::kMeasurementPoints; ++p) {
    dsp::add_unexplained_energy(measured[p].data(), measured[p].size(), simulated[p].data(),
                                simulated[p].size(), last_line, miss, total);
  }
  return total > 0.0 ? miss / total : 1.0;
}

// The residual as reported: the share above clipped to [0, 1].
double residual(const std::array<std::vector<double>, mc::kMeasurementPoints>& measured,
                const std::array<std::vector<double>, mc::kMeasurementPoints>& simulated,
                std::size_t last_line) {
  return std::clamp(residual_unclipped(measured, simulated, last_line), 0.0, 1.0);
}

// What carries the residual: the lines (local maxima of max(measured, simulated) over the
// Hann main lobe, ±2 lines) whose lobes hold the most of Σ(a_m − a_s)², each named by the
// nearest kinematic family of the description (mesh harmonics, shaft harmonics, bearings'
// ball-pass harmonics and sums of two: a bearing's varying compliance) within ±1 line.
struct ResidualLine {
  std::size_t point = 0;
  double hz = 0.0;
  double order = 0.0;  // [hss orders]
  double measured = 0.0;
  double simulated = 0.0;
  double share = 0.0;  // of the recording's energy at both points, 0–5 kHz
  std::string family;
};

std::string line_family(const model::Drivetrain& d, const model::Kinematics& k, double rpm,
                        double hz, double tolerance_hz) {
  std::string best = "-";
  double best_err = tolerance_hz;
  const auto consider = [&](double f, const std::string& name) {
    if (f > 0.0 && std::abs(f - hz) <= best_err) {
      best_err = std::abs(f - hz);
      best = name;
    }
  };
  static const char* const kStage[] = {"planetary mesh", "intermediate mesh", "high-speed mesh"};
  for (std::size_t s = 0; s < d.stages.size() && s < 3; ++s)
    for (int h = 1; h <= 40; ++h)
      consider(h * k.mesh_hz(s, rpm), std::to_string(h) + "x " + kStage[s]);
  for (const model::Shaft& sh : d.shafts) {
    const std::optional<double> f = k.shaft_hz(sh.id, rpm);
    if (!f) continue;
    for (int h = 1; h <= 6; ++h) consider(h * *f, std::to_string(h) + "x " + sh.id);
  }
  std::vector<std::pair<std::string, double>> bpfo;
  for (const model::Bearing& b : d.bearings) {
    const std::optional<model::BearingFrequencies> f = k.bearing_hz(b.id, rpm);
    if (!f) continue;
    bpfo.emplace_back(b.id, f->bpfo_hz);
    for (int h = 1; h <= 4; ++h) consider(h * f->bpfo_hz, std::to_string(h) + "x BPFO " + b.id);
  }
  for (std::size_t i = 0; i < bpfo.size(); ++i)
    for (std::size_t j = i + 1; j < bpfo.size(); ++j)
      consider(bpfo[i].second + bpfo[j].second,
               "BPFO " + bpfo[i].first + " + BPFO " + bpfo[j].first);
  return best;
}

std::vector<ResidualLine> residual_lines(
    const std::array<std::vector<double>, mc::kMeasurementPoints>& measured,
    const std::array<std::vector<double>, mc::kMeasurementPoints>& simulated, std::size_t last_line,
    std::size_t revolutions, double hss_hz, const model::Drivetrain& d, const model::Kinematics& k,
    double rpm, std::size_t per_point) {
  double total = 0.0;
  for (std::size_t p = 0; p < mc::kMeasurementPoints; ++p)
    for (std::size_t i = 1; i <= last_line && i < measured[p].size(); ++i)
      total += measured[p][i] * measured[p][i];
  std::vector<ResidualLine> out;
  if (!(total > 0.0)) return out;
  const double line_hz = hss_hz / static_cast<double>(revolutions);
  for (std::size_t p = 0; p < mc::kMeasurementPoints; ++p) {
    const std::size_t n = std::min(last_line + 1, measured[p].size());
    std::vector<ResidualLine> lines;
    for (std::size_t i = 3; i + 2 < n; ++i) {
      const auto peak = [&](std::size_t j) { return std::max(measured[p][j], simulated[p][j]); };
      bool is_max = true;
      for (std::size_t j = i - 2; j <= i + 2; ++j)
        if (j != i && peak(j) > peak(i)) is_max = false;
      if (!is_max) continue;
      double miss = 0.0;
      for (std::size_t j = i - 2; j <= i + 2; ++j) {
        const double dd = measured[p][j] - simulated[p][j];
        miss += dd * dd;
      }
      ResidualLine r;
      r.point = p;
      r.order = static_cast<double>(i) / static_cast<double>(revolutions);
      r.hz = static_cast<double>(i) * line_hz;
      r.measured = measured[p][i];
      r.simulated = simulated[p][i];
      r.share = miss / total;
      lines.push_back(r);
    }
    const std::size_t keep = std::min(per_point, lines.size());
    std::partial_sort(
        lines.begin(), lines.begin() + static_cast<std::ptrdiff_t>(keep), lines.end(),
        [](const ResidualLine& a, const ResidualLine& b) { return a.share > b.share; });
    for (std::size_t i = 0; i < keep; ++i) {
      lines[i].family = line_family(d, k, rpm, lines[i].hz, line_hz);
      out.push_back(lines[i]);
    }
  }
  return out;
}

nlohmann::json residual_lines_json(const std::vector<ResidualLine>& lines) {
  nlohmann::json list = nlohmann::json::array();
  for (const ResidualLine& r : lines) {
    list.push_back({{"point", r.point + 1},
                    {"hz", r.hz},
                    {"order", r.order},
                    {"measured", r.measured},
                    {"simulated", r.simulated},
                    {"share", r.share},
                    {"family", r.family}});
  }
  return list;
}

// One bundle, measured: its calibration case (features averaged over its windows), the
// average order spectrum for the residual, and what the output names.

// One space's calibration: printed as it runs; its JSON and parameters for run() to keep.
struct Attempt {
  std::string space;
  bool success = false;
  mc::SpaceOutcome outcome;
  double seconds = 0.0;
  model::Drivetrain drivetrain;
  model::DynamicsParameters parameters;
  nlohmann::json json;
};

Attempt attempt(const CalibrateArgs& args, const std::string& space_name) {
  if (args.bundles.size() > mc::kMaxCalibrationCases) {
    throw CommandError("calibrate: at most " + std::to_string(mc::kMaxCalibrationCases) +
                       " bundles (operating points) calibrate jointly; got " +
                       std::to_string(args.bundles.size()));
  }
  if (args.windows == 0 || args.windows > 64) throw CommandError("--windows: expected 1..64");
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
  if (args.simulator != "rom" && args.simulator != "lumped")
    throw CommandError("--simulator: expected 'rom' or 'lumped', got '" + args.simulator + "'");

  // The drivetrain: --drivetrain, else the first bundle's; every bundle must name the same.
  app::recording::CheckedBundle first;
  try {
    first = app::recording::load_bundle(args.bundles.front(), {args.drivetrain});
  } catch (const app::recording::BundleCheckError& e) {
    throw CommandError(e.what());
  }
  const model::Drivetrain drivetrain = first.drivetrain;
  const std::string drivetrain_source =
      args.drivetrain.empty() ? first.drivetrain_source : args.drivetrain;
  const model::Kinematics kinematics(drivetrain);

  dsp::FeatureConfig fc;
  fc.samples_per_rev = args.samples_per_rev;
  fc.revolutions = args.revolutions;
  fc.harmonics = args.harmonics;
  cc.mogoa.population = args.population;
  cc.mogoa.max_iterations = args.iterations;
  cc.mogoa.seed = args.seed;
  cc.trust_region.max_evaluations = args.evaluations;
  cc.warm_rounds = !args.probe_every_round;
  cc.residual_model_sd = args.residual_sd;
  cc.residual_band_hz = kCalibrateResidualBandHz;
  cc.trust_region.seed = app::recording::calibrate_trust_region_seed(args.seed);
  // --space body: the gearbox body on its mounts joins the model, at the description's values
  // or the engineering prior (calibration_space.hpp); "before" is that model's.
  const model::DynamicsParameters prior =
      space_name == "body"
          ? mc::with_nominal_gearbox_body(mc::with_nominal_damping(drivetrain.dynamics))
          : mc::with_nominal_damping(drivetrain.dynamics);
  if (prior.rayleigh_eta != drivetrain.dynamics.rayleigh_eta) {
    std::fprintf(stderr,
                 "calibrate: note: drivetrain '%s' has no damping; starting from eta %.3g 1/s, "
                 "zeta %.3g s\n",
                 drivetrain.name.c_str(), prior.rayleigh_eta, prior.rayleigh_zeta);
  }
  cc.space = space_name == "paper"
                 ? mc::CalibrationSpace::paper(prior)
                 : mc::default_space(drivetrain, space_name == "seats", space_name == "body");
  if (cc.space.overflow() > 0) {
    throw CommandError("--space " + space_name + ": drivetrain '" + drivetrain.name + "' needs " +
                       std::to_string(cc.space.size() + cc.space.overflow()) +
                       " calibration variables; the calibrator holds " +
                       std::to_string(mc::kMaxCalibrationVariables) + " (use --space standard)");
  }

  // The simulator runs at the first recording's rate (the rate the twin's ROM runs at).
  const double rate_hz =
      app::recording::calibrate_simulator_rate_hz(first.recording.sample_rate_hz);
  std::unique_ptr<mc::VibrationSimulator> simulator;
  if (args.simulator == "lumped") {
    mc::LumpedSimulatorConfig sc;
    sc.harmonics = args.harmonics;
    double slowest_rpm = 1e9;
    (void)slowest_rpm;
    sc.max_duration_s = 4.0 * static_cast<double>(args.revolutions + 4) /
                        (std::max(first.recording.operating_point.rotor_speed_rpm, 1e-3) / 60.0 *
                         kinematics.overall_ratio());
    const double top_hz = kinematics.mesh_hz(kinematics.stage_count() - 1,
                                             drivetrain.turbine.rated_rotor_speed_rpm > 0
                                                 ? drivetrain.turbine.rated_rotor_speed_rpm
                                                 : 20.0) *
                          static_cast<double>(args.harmonics);
    sc.sample_rate_hz = std::max(4096.0, std::exp2(std::ceil(std::log2(4.0 * top_hz))));
    simulator = std::make_unique<mc::LumpedSimulator>(drivetrain, sc);
  } else {
    simulator =
        std::make_unique<mc::DynamicsSimulator>(drivetrain, mc::DynamicsModel::kRom, rate_hz, 0.5);
  }
  auto calibrator = std::make_unique<mc::Calibrator>(*simulator, drivetrain, fc, cc);
  if (calibrator->status() != dsp::DspStatus::kOk) {
    throw CommandError("--revolutions/--samples-per-rev/--harmonics: " +
                       std::string(dsp::to_string(calibrator->status())));
  }
  dsp::FeatureExtractor fx(calibrator->feature_config());

  std::vector<MeasuredBundle> bundles;
  for (const std::string& b : args.bundles) {
    try {
      bundles.push_back(app::recording::measure_for_calibration(
          b, args.windows, fx, args.drivetrain.empty() ? drivetrain_source : args.drivetrain));
    } catch (const app::recording::BundleCheckError& e) {
      throw CommandError(e.what());
    }
    for (const auto& note : bundles.back().bundle.notes)
      std::fprintf(stderr, "calibrate: note: %s\n", note.c_str());
    if (bundles.back().bundle.drivetrain.name != drivetrain.name) {
      throw CommandError(b + ": drivetrain '" + bundles.back().bundle.drivetrain.name +
                         "' differs from the first bundle's '" + drivetrain.name +
                         "'; a joint calibration fits one drivetrain (--drivetrain to choose)");
    }
  }
  std::vector<mc::CalibrationCase> cases;
  for (const MeasuredBundle& b : bundles) cases.push_back(b.measured);
  const auto load_measurements = [&](mc::Calibrator& cal) {
    if (!cal.set_measurements(cases.data(), cases.size()))
      throw CommandError("calibrate: too many features for the calibration's capacity");
    // The fit also weighs the spectral residual against each point's averaged order spectrum.
    for (std::size_t c = 0; c < bundles.size(); ++c) {
      for (std::size_t p = 0; p < mc::kMeasurementPoints; ++p) {
        const std::vector<double>& sp = bundles[c].spectrum[p];
        (void)cal.set_measured_spectrum(c, p, sp.data(), sp.size());
      }
    }
  };
  load_measurements(*calibrator);

  // A parameter set simulated at bundle c: its features and order spectra.
  struct Simulated {
    std::array<dsp::PointFeatures, mc::kMeasurementPoints> features{};
    std::array<std::vector<double>, mc::kMeasurementPoints> spectrum;
  };
  auto simulate_at = [&](const model::DynamicsParameters& params, std::size_t c) {
    const MeasuredBundle& b = bundles[c];
    Simulated out;
    std::array<mc::WaveformView, mc::kMeasurementPoints> w{};
    const double ref_hz = b.hss_hz;
    const bool ok = simulator->simulate(params, b.measured.op,
                                        fx.required_duration_s(ref_hz) + 1.0 / ref_hz, w);
    for (std::size_t p = 0; p < mc::kMeasurementPoints; ++p) {
      if (ok && fx.extract(w[p].samples, w[p].count, w[p].sample_rate_hz, {nullptr, 0, ref_hz},
                           out.features[p]) == dsp::DspStatus::kOk) {
        out.spectrum[p].assign(fx.order_spectrum(), fx.order_spectrum() + b.spectrum[p].size());
      } else {
        out.features[p] = {};
        out.spectrum[p].assign(b.spectrum[p].size(), 0.0);
      }
    }
    return out;
  };
  auto residual_last_line = [&](std::size_t c) {  // the last order line below 5 kHz
    return static_cast<std::size_t>(kCalibrateResidualBandHz / bundles[c].hss_hz *
                                    static_cast<double>(fx.config().revolutions));
  };
  auto residual_of_simulated = [&](const Simulated& sim, std::size_t c) {
    return residual(bundles[c].spectrum, sim.spectrum, residual_last_line(c));
  };
  auto residual_unclipped_of = [&](const Simulated& sim, std::size_t c) {
    return residual_unclipped(bundles[c].spectrum, sim.spectrum, residual_last_line(c));
  };
  auto residual_lines_of = [&](const Simulated& sim, std::size_t c) {
    const MeasuredBundle& b = bundles[c];
    return residual_lines(b.spectrum, sim.spectrum, residual_last_line(c), fx.config().revolutions,
                          b.hss_hz, drivetrain, kinematics, b.measured.op.rotor_speed_rpm, 8);
  };

  std::array<mc::PointIndicators, mc::kMaxCalibrationCases> fit_before{};
  if (!calibrator->evaluate_cases(prior, fit_before))
    throw CommandError("simulation failed at the starting parameters");
  std::vector<double> residual_before;
  std::vector<Simulated> sim_before;
  bool needs = false;
  for (std::size_t c = 0; c < bundles.size(); ++c) {
    sim_before.push_back(simulate_at(prior, c));
    residual_before.push_back(residual_of_simulated(sim_before.back(), c));
    needs = needs || mc::needs_calibration(fit_before[c]);
  }

  const mc::CalibrationSpace& space = calibrator->space();
  if (!args.quiet) {
    std::printf("drivetrain %s; simulator: %s\n", drivetrain.name.c_str(),
                args.simulator == "rom" ? "dynamics ROM (model/dynamics, simulate_rom)"
                                        : "lumped stand-in (not the dynamics ROM)");
    for (std::size_t c = 0; c < bundles.size(); ++c) {
      const MeasuredBundle& b = bundles[c];
      std::printf("bundle %s: rotor %.3f rpm (speed from %s), torque %.0f N·m, %zu window%s\n",
                  b.dir.string().c_str(), b.measured.op.rotor_speed_rpm, b.speed_source.c_str(),
                  b.measured.op.input_torque_nm, b.windows, b.windows == 1 ? "" : "s");
      print_fit("fit before:", fit_before[c]);
      std::printf("residual before: %.3f (unclipped %.3f)\n", residual_before[c],
                  residual_unclipped_of(sim_before[c], c));
    }
  }

  mc::CalibrationResult result;
  result.parameters = prior;
  result.case_indicators = fit_before;
  result.indicators = fit_before[0];
  result.fits = !needs;
  const bool run_optimizer = args.force || needs;
  double seconds = 0.0;
  // A resonance the local fit cannot move (model/calibration/resonance_placement.hpp): after
  // the fit, the sun shaft's torsion scanned over prior ×/÷ 9; where the summed unclipped
  // residual is lower at another grid point, a refit from there with the scale released (a
  // variable centred on the description: with_sun_shaft_torsion), and the better of the two
  // kept (docs/calibration.md, Sessions 14 and 15).
  nlohmann::json placement = nullptr;
  // The space of the fit reported: the first fit's, or the released refit's when it is kept.
  const mc::CalibrationSpace* fitted_space = &calibrator->space();
  std::unique_ptr<mc::Calibrator> released;  // the refit's calibrator, kept for its space
  const auto place_resonance = [&](mc::CalibrationResult& res, const auto& run_from) {
    const auto summed_residual = [&](const model::DynamicsParameters& p) {
      double sum = 0.0;
      for (std::size_t c = 0; c < bundles.size(); ++c)
        sum += residual_unclipped_of(simulate_at(p, c), c);
      return sum;
    };
    // Any fall: the scan holds the other variables at values fitted under the first mode, so
    // its fall is a lower bound on what a refit gains (Session 14: falls of 0.058 and 0.070
    // became 0.37 and 0.08), and the keep rule below guards the first fit.
    const mc::PlacementScan scan = mc::scan_placement(prior, res.parameters, 0.0, summed_residual);
    nlohmann::json grid = nlohmann::json::array();
    for (std::size_t g = 0; g < mc::kPlacementPoints; ++g)
      grid.push_back({{"value", scan.value[g]}, {"residual_unclipped", scan.residual[g]}});
    placement = {{"parameter", "sun_shaft_torsion_scale"},
                 {"fitted", scan.fitted},
                 {"residual_unclipped_at_fit", scan.fitted_residual},
                 {"grid", grid},
                 {"best", scan.best},
                 {"refit", scan.refit}};
    if (!args.quiet) {
      std::printf(
          "resonance placement: sun_shaft_torsion_scale %.3g (residual %.3f); over "
          "%.3g..%.3g the lowest at %.3g (%.3f)%s\n",
          scan.fitted, scan.fitted_residual, scan.value.front(), scan.value.back(), scan.best,
          scan.best_residual, scan.refit ? ": fitting again there" : "");
    }
    if (!scan.refit) return;
    model::DynamicsParameters from = res.parameters;
    from.sun_shaft_torsion_scale = scan.best;
    // The refit releases the scale: the scan's grid is ×1.63 coarse, and the other variables
    // move with the mode. Where the space is full, the scale stays fixed at the scan's best.
    mc::CalibratorConfig rc = cc;
    rc.space = calibrator->space().with_sun_shaft_torsion();
    const bool release = rc.space.overflow() == 0;
    if (release) {
      released = std::make_unique<mc::Calibrator>(*simulator, drivetrain, fc, rc);
      load_measurements(*released);
      std::swap(calibrator, released);
    }
    mc::CalibrationResult again;
    run_from(from, again);
    if (release) std::swap(calibrator, released);
    const double residual_again = summed_residual(again.parameters);
    const bool keep = mc::keep_refit(res.fits && !res.at_bound, scan.fitted_residual,
                                     mc::worst_case_ratio(res.case_indicators, bundles.size()),
                                     again.fits && !again.at_bound, residual_again,
                                     mc::worst_case_ratio(again.case_indicators, bundles.size()));
    placement["released"] = release;
    placement["refit_value"] = again.parameters.sun_shaft_torsion_scale;
    placement["residual_unclipped_refit"] = residual_again;
    placement["kept"] = keep ? "refit" : "first fit";
    if (!args.quiet) {
      std::printf(
          "resonance placement: the refit (sun_shaft_torsion_scale %s, ends at %.3g) %s "
          "(residual %.3f against %.3f; it %s)\n",
          release ? "released" : "fixed", again.parameters.sun_shaft_torsion_scale,
          keep ? "is kept" : "is not kept", residual_again, scan.fitted_residual,
          again.fits && !again.at_bound ? "calibrates" : "does not calibrate");
    }
    // Evaluations: both fits'; the first fitting evaluation counted from the first fit's start.
    const std::size_t first_evaluations = res.evaluations;
    const std::size_t first_threshold = res.evaluations_to_threshold;
    if (keep) {
      res = again;
      if (release) fitted_space = &released->space();
    }
    res.evaluations = first_evaluations + again.evaluations;
    // 0 when neither fit reached the thresholds.
    std::size_t to_threshold = first_threshold;
    if (to_threshold == 0 && again.evaluations_to_threshold > 0)
      to_threshold = first_evaluations + again.evaluations_to_threshold;
    res.evaluations_to_threshold = to_threshold;
  };
  if (!run_optimizer) {
    if (!args.quiet) std::printf("every indicator within its threshold: no calibration needed\n");
  } else {
    if (!args.quiet) {
      if (cc.method == mc::CalibrationMethod::kTrustRegion) {
        std::printf(
            "calibrating %zu variables (%s space): up to %zu rounds of excitation solve, "
            "identification (%zu probes%s) and at most %zu evaluations of the fit\n",
            space.size(), space_name.c_str(), cc.max_rounds, space.size(),
            cc.warm_rounds ? "; a round after one that improved reuses its model" : "",
            args.evaluations);
      } else {
        std::printf(
            "calibrating %zu variables: %s MOGOA, %zu grasshoppers x %zu iterations, seed %llu\n",
            space.size(), args.method.c_str(), args.population, args.iterations,
            static_cast<unsigned long long>(args.seed));
      }
    }
    // One run of the calibrator from `from` (the space's prior stays the description's).
    const auto run = [&](const model::DynamicsParameters& from, mc::CalibrationResult& out) {
      const auto t0 = std::chrono::steady_clock::now();
      calibrator->start(from);
      mc::StepStatus st;
      std::size_t last_print = 0;
      while ((st = calibrator->step()) == mc::StepStatus::kRunning) {
        const std::size_t e = calibrator->evaluations();
        if (!args.quiet && (e >= last_print + 10 || e == 1)) {
          last_print = e;
          // Before the first evaluation's indicators are in, the best ratio is a sentinel.
          const double best = calibrator->best_ratio();
          char best_text[32] = "-";
          if (best < 1e6) std::snprintf(best_text, sizeof best_text, "%.3f", best);
          std::printf("  evaluation %4zu  %s  best worst-indicator/threshold %s%s\n", e,
                      cc.method != mc::CalibrationMethod::kTrustRegion ? "fitting    "
                      : calibrator->reading_excitation()               ? "excitation "
                      : calibrator->identifying()                      ? "identifying"
                                                                       : "fitting    ",
                      best_text, calibrator->evaluations_to_threshold() ? "  (fit found)" : "");
          std::fflush(stdout);
        }
      }
      const double run_seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      seconds += run_seconds;
      if (!calibrator->read_result(out)) throw CommandError("calibration published no result");
      if (!args.quiet) {
        std::printf(
            "done: %zu evaluations in %.1f s (%zu rounds, %zu of them probed); first fitting "
            "evaluation: %zu; %zu of %zu variables identified\n",
            out.evaluations, run_seconds, out.rounds, out.probed_rounds,
            out.evaluations_to_threshold, out.identified, out.variables);
      }
    };
    run(prior, result);
    if (cc.method == mc::CalibrationMethod::kTrustRegion && args.simulator == "rom" &&
        space_name != "paper")
      place_resonance(result, run);
  }
  std::vector<double> residual_after;
  std::vector<Simulated> sim_after;
  for (std::size_t c = 0; c < bundles.size(); ++c) {
    sim_after.push_back(simulate_at(result.parameters, c));
    residual_after.push_back(residual_of_simulated(sim_after.back(), c));
  }
  // Every compared tone: its order, the measured amplitude and floor, before and after.
  auto tone_rows = [&](std::size_t c) {
    std::vector<ToneRow> rows;
    const MeasuredBundle& b = bundles[c];
    const double rpm = b.measured.op.rotor_speed_rpm;
    for (std::size_t p = 0; p < mc::kMeasurementPoints; ++p) {
      const dsp::PointFeatures& m = b.measured.measured[p];
      for (std::size_t i = 0; i < m.count; ++i) {
        ToneRow r;
        r.point = p;
        r.stage = i / fc.harmonics;
        r.harmonic = i % fc.harmonics + 1;
        r.order = kinematics.mesh_hz(r.stage, rpm) / b.hss_hz * static_cast<double>(r.harmonic);
        r.measured = m.amplitude[i];
        r.floor = m.noise_floor[i];
        r.resolved = m.resolved[i];
        r.before = sim_before[c].features[p].amplitude[i];
        r.after = sim_after[c].features[p].amplitude[i];
        rows.push_back(r);
      }
    }
    return rows;
  };
  const bool success = result.fits && !result.at_bound;
  if (!args.quiet) {
    if (run_optimizer) {
      // A variable not identified keeps its start: the prior, or, for the sun shaft's torsion
      // released in the placement's refit, the value the scan placed it at.
      std::printf(
          "variables (value = start unless identified: the prior, or the placement's for "
          "the sun shaft; sd/pr = posterior/prior sd):\n");
      print_variables(*fitted_space, result);
    }
    for (std::size_t c = 0; c < bundles.size(); ++c) {
      std::printf("bundle %s:\n", bundles[c].dir.string().c_str());
      print_fit("fit calibrated:", result.case_indicators[c]);
      std::printf("residual calibrated: %.3f (unclipped %.3f); the lines that carry it:\n",
                  residual_after[c], residual_unclipped_of(sim_after[c], c));
      std::printf("  point  Hz        order    measured  simulated  share  family\n");
      for (const ResidualLine& r : residual_lines_of(sim_after[c], c)) {
        std::printf("  %zu      %8.1f  %7.3f  %8.4f  %9.4f  %5.3f  %s\n", r.point + 1, r.hz,
                    r.order, r.measured, r.simulated, r.share, r.family.c_str());
      }
      print_tones(tone_rows(c));
    }
    if (success) {
      std::printf("CALIBRATED: every indicator within its threshold at both points%s\n",
                  bundles.size() > 1 ? " of every bundle" : "");
    } else if (result.fits) {
      std::printf(
          "NOT CALIBRATED: the indicators are within their thresholds only with a "
          "variable at its bound (marked AT ... BOUND): the recording asks for more than "
          "its physical range — missing physics or a wrong prior\n");
    } else {
      std::printf("NOT CALIBRATED: some indicator remains above its threshold (marked *)\n");
    }
  }

  Attempt out;
  out.space = space_name;
  out.success = success;
  out.outcome = {success, mc::worst_case_ratio(result.case_indicators, bundles.size())};
  out.seconds = seconds;
  out.drivetrain = drivetrain;
  out.parameters = result.parameters;
  {
    nlohmann::json& j = out.json;
    j["format"] = "drivetwin-calibration/2";
    const auto name_of = [](const fs::path& dir) {
      return dir.filename().string().empty() ? dir.parent_path().filename().string()
                                             : dir.filename().string();
    };
    j["bundle"] = name_of(bundles.front().dir);
    j["operating_point"] = {{"rotor_speed_rpm", bundles.front().measured.op.rotor_speed_rpm},
                            {"input_torque_nm", bundles.front().measured.op.input_torque_nm}};
    j["speed_source"] = bundles.front().speed_source;
    j["simulator"] = args.simulator == "rom" ? "dynamics-rom" : "lumped-stand-in";
    j["method"] = args.method;
    j["space"] = space_name;
    j["fit_before"] = fit_json(fit_before[0]);
    j["fit_calibrated"] = fit_json(result.case_indicators[0]);
    j["residual_before"] = residual_before[0];
    j["residual_calibrated"] = residual_after[0];
    nlohmann::json cases_json = nlohmann::json::array();
    for (std::size_t c = 0; c < bundles.size(); ++c) {
      cases_json.push_back(
          {{"bundle", name_of(bundles[c].dir)},
           {"operating_point",
            {{"rotor_speed_rpm", bundles[c].measured.op.rotor_speed_rpm},
             {"input_torque_nm", bundles[c].measured.op.input_torque_nm}}},
           {"windows", bundles[c].windows},
           {"fit_before", fit_json(fit_before[c])},
           {"fit_calibrated", fit_json(result.case_indicators[c])},
           {"residual_before", residual_before[c]},
           {"residual_calibrated", residual_after[c]},
           {"residual_before_unclipped", residual_unclipped_of(sim_before[c], c)},
           {"residual_calibrated_unclipped", residual_unclipped_of(sim_after[c], c)},
           {"residual_lines_before", residual_lines_json(residual_lines_of(sim_before[c], c))},
           {"residual_lines_calibrated", residual_lines_json(residual_lines_of(sim_after[c], c))},
           {"tones", tones_json(tone_rows(c))}});
    }
    j["cases"] = cases_json;
    j["variables"] = variables_json(*fitted_space, result, run_optimizer);
    j["parameters_calibrated"] = params_json(result.parameters);
    j["calibration_ran"] = run_optimizer;
    j["resonance_placement"] = placement;
    j["fits"] = result.fits;
    j["at_bound"] = result.at_bound;
    j["calibrated"] = success;
    j["identified"] = result.identified;
    j["evaluations"] = result.evaluations;
    j["evaluations_to_threshold"] = result.evaluations_to_threshold;
    j["rounds"] = result.rounds;
    j["probed_rounds"] = result.probed_rounds;
    j["seconds"] = seconds;
  }
  return out;
}

// --space auto (the default with the ROM): the standard space; when it does not calibrate,
// the standard + body space from the same start, and of the two the one mc::choose_space
// keeps (nested-model selection, docs/calibration.md).
void run(const CalibrateArgs& args) {
  const bool auto_space = args.space.empty() || args.space == "auto";
  if (auto_space && args.simulator == "lumped" && args.space == "auto")
    throw CommandError("--space auto: the lumped stand-in knows only the paper space");
  // The lumped stand-in knows only the paper's 8 variables.
  const std::string first_space = !auto_space                  ? args.space
                                  : args.simulator == "lumped" ? "paper"
                                                               : "standard";
  Attempt chosen = attempt(args, first_space);
  if (auto_space && args.simulator != "lumped") {
    nlohmann::json selection = {
        {"rule",
         "standard; standard+body only when standard does not calibrate; keep the one that "
         "calibrates, else the lower worst indicator/threshold (standard on a tie)"}};
    nlohmann::json tried = nlohmann::json::array();
    tried.push_back({{"space", chosen.space},
                     {"calibrated", chosen.success},
                     {"worst_ratio", chosen.outcome.worst_ratio},
                     {"seconds", chosen.seconds}});
    std::string reason;
    if (!mc::should_try_richer(chosen.outcome)) {
      reason = "the standard space calibrates: the body is not tried";
    } else {
      if (!args.quiet) {
        std::printf(
            "model selection: the standard space did not calibrate (worst indicator/threshold "
            "%.3f); fitting standard + gearbox body from the same start\n",
            chosen.outcome.worst_ratio);
        std::fflush(stdout);
      }
      Attempt richer = attempt(args, "body");
      tried.push_back({{"space", richer.space},
                       {"calibrated", richer.success},
                       {"worst_ratio", richer.outcome.worst_ratio},
                       {"seconds", richer.seconds}});
      const bool keep_richer =
          mc::choose_space(chosen.outcome, richer.outcome) == mc::SpaceChoice::kRicher;
      char text[160];
      if (chosen.success != richer.success) {
        std::snprintf(text, sizeof text, "only the %s space calibrates",
                      richer.success ? "body" : "standard");
      } else {
        std::snprintf(text, sizeof text,
                      "%s calibrates; worst indicator/threshold standard %.3f, body %.3f",
                      chosen.success ? "each" : "neither", chosen.outcome.worst_ratio,
                      richer.outcome.worst_ratio);
      }
      reason = text;
      if (keep_richer) chosen = std::move(richer);
    }
    selection["tried"] = tried;
    selection["chosen"] = chosen.space;
    selection["reason"] = reason;
    chosen.json["model_selection"] = selection;
    if (!args.quiet) {
      std::printf("model selection: %s space kept (%s): %s\n", chosen.space.c_str(), reason.c_str(),
                  chosen.success ? "CALIBRATED" : "NOT CALIBRATED");
    }
  }
  if (!args.json.empty()) {
    std::ofstream out(args.json);
    out << chosen.json.dump(2) << "\n";
    if (!out) throw CommandError(args.json + ": cannot write");
  }
  const bool success = chosen.success;
  const model::Drivetrain& drivetrain = chosen.drivetrain;
  if (!args.update.empty()) {
    if (!success) {
      std::fprintf(stderr, "calibrate: --update %s: not written (the result is NOT CALIBRATED)\n",
                   args.update.c_str());
    } else {
      // FILE's own description when it exists (its other keys are kept), else the one calibrated.
      model::Drivetrain d = drivetrain;
      std::error_code ec;
      if (fs::exists(args.update, ec)) {
        try {
          d = app::config::load_drivetrain(args.update);
        } catch (const app::config::DrivetrainFileError& e) {
          throw CommandError(std::string("--update: ") + e.what());
        }
      }
      d.dynamics = chosen.parameters;
      const std::string tmp = args.update + ".tmp";
      {
        std::ofstream out(tmp);
        out << app::config::to_toml(d);
        if (!out) throw CommandError("--update: " + tmp + ": cannot write");
      }
      if (std::rename(tmp.c_str(), args.update.c_str()) != 0)
        throw CommandError("--update: " + args.update + ": cannot replace");
      if (!args.quiet)
        std::printf("wrote the calibrated parameters into %s\n", args.update.c_str());
    }
  }
  if (!success) app::cli::exit_status() = 2;
}

void setup_calibrate(CLI::App& sub) {
  auto args = std::make_shared<CalibrateArgs>();
  sub.add_option("bundles", args->bundles,
                 "Recording bundle directories (drivetwin-recording/1); several: one parameter "
                 "set fitted to all (joint calibration over operating points)")
      ->required();
  sub.add_option("--json", args->json, "Write the result as JSON to this file");
  sub.add_option("--update", args->update,
                 "Write the calibrated parameters into this drivetrain description (when "
                 "CALIBRATED)");
  sub.add_option("--drivetrain", args->drivetrain, "Drivetrain NAME|FILE (default: the bundle's)");
  sub.add_option("--method", args->method, "trust-region (default), improved or published MOGOA")
      ->check(app::cli::one_of({"trust-region", "improved", "published"}));
  sub.add_option("--space", args->space,
                 "auto (default with the ROM: standard, and standard + body only when standard "
                 "does not calibrate, keeping the one that calibrates), standard (damping, "
                 "stiffness, transmission error with "
                 "its phase, housing modes), seats (standard + each housing mode's participation "
                 "at the seats of the bearings without a sensor), body (standard + the gearbox "
                 "body on its mounts: mass, mount stiffness and damping, from an engineering "
                 "prior where the description has none) or paper (the paper's 8 variables; the "
                 "default with the lumped stand-in)")
      ->check(app::cli::one_of({"auto", "standard", "seats", "body", "paper"}));
  sub.add_option("--simulator", args->simulator,
                 "rom (default, the dynamics ROM) or lumped (stand-in)")
      ->check(app::cli::one_of({"rom", "lumped"}));
  sub.add_option("--evaluations", args->evaluations,
                 "trust-region: model evaluations of each round's fit at most (default 30; "
                 "up to 8 rounds, each with its excitation solve and identification probes on "
                 "top; a warm round probes nothing)")
      ->check(app::cli::integer_in(0, 100000, "model evaluations"));
  sub.add_flag("--probe-every-round", args->probe_every_round,
               "trust-region: probe every variable in every round (no warm rounds, which reuse "
               "the model of a round that improved the fit)");
  sub.add_option("--population", args->population, "Grasshoppers (default 20)")
      ->check(app::cli::integer_in(2, 64, "grasshoppers"));
  sub.add_option("--iterations", args->iterations, "MOGOA iterations (default 50)")
      ->check(app::cli::integer_in(1, 100000, "iterations"));
  sub.add_option("--seed", args->seed,
                 "Random seed (default 1; MOGOA's population, the trust region's restart points)")
      ->check(app::cli::integer_in(0, std::numeric_limits<long long>::max(), "seed"));
  sub.add_option("--revolutions", args->revolutions,
                 "hss revolutions per analysis block (default 64)")
      ->check(app::cli::integer_in(8, 4096, "hss revolutions"));
  sub.add_option("--windows", args->windows,
                 "Analysis blocks per bundle, averaged (default 4, as many as the recording has)")
      ->check(app::cli::integer_in(1, 64, "analysis blocks"));
  sub.add_option("--samples-per-rev", args->samples_per_rev,
                 "Angle-domain samples per hss revolution (default 1024)")
      ->check(app::cli::integer_in(16, 65536, "samples per revolution"));
  sub.add_option("--harmonics", args->harmonics,
                 "Mesh harmonics compared, fundamental included (default 3)")
      ->check(app::cli::integer_in(1, 10, "harmonics"));
  sub.add_option("--residual-sd", args->residual_sd,
                 "Uncertainty of the spectral residual in the fit's last rounds (default 0.25; "
                 "0: tones and RMS only)")
      ->check(app::cli::number_in(0.0, 10.0));
  sub.add_flag("--force", args->force,
               "Calibrate even when every indicator is within its threshold");
  sub.add_flag("--quiet", args->quiet, "Print nothing but errors");
  sub.callback([args] { run(*args); });
}

const bool kCalibrateRegistered = app::cli::register_command(
    {"calibrate",
     "Similarity indicators f1/f2/f3 against recordings; calibration when above threshold",
     &setup_calibrate});

}  // namespace
