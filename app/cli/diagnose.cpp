// `drivetwin diagnose <bundle> [--json report.json] [--html report.html]`: when
// simulation and recording differ in a way calibration cannot remove, locate the
// mismatch, name the physics the model left out, model it, refit, and show the fit
// (model/diagnosis/diagnoser.hpp; docs/diagnosis.md).
//
// Reads a recording bundle (shared/reference/recording-bundle.md), calibrates the
// twin's ROM against it, analyses what is left, ranks the effects of the diagnosis
// contract by how well their kinematic signature explains it, fits the best ones with
// their dynamics term switched on, and reports an effect only when it explains
// significantly more than calibration alone on the half of the recording it was not
// fitted to. Writes shared/reference/diagnosis-report.md's JSON and an offline HTML
// report.
//
// Exit status: 0 when the diagnosis ran (whatever it found), 1 for a bad bundle or a
// failed run (a message names the file, the field and what was expected; nothing is
// written).
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "cli/command.hpp"
#include "cli/options.hpp"
#include "diagnosis/report.hpp"
#include "hal/recording_bundle.hpp"
#include "model/diagnosis/diagnoser.hpp"
#include "model/drivetrain/kinematics.hpp"
#include "model/dsp/order_tracking.hpp"
#include "recording/bundle_check.hpp"

namespace {
namespace diagnose_cmd {

namespace fs = std::filesystem;
namespace md = model::diagnosis;
using app::cli::CommandError;

struct Args {
  std::string bundle;
  std::string json;
  std::string html;
  std::string drivetrain;
  std::size_t evaluations = model::calibration::kDefaultFitEvaluations;
  std::size_t candidates = 3;
  std::size_t fit_evaluations = 10;
  bool probe_every_round = false;
  bool quiet = false;
};

// Writes `text` to `path` through a temporary file renamed into place.
void write_file(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    out << text;
    if (!out) throw CommandError(path + ": cannot write");
  }
  fs::rename(tmp, path);
}

void run(const Args& args) {
  const fs::path dir(args.bundle);
  // The bundle validation layer (app/recording/bundle_check.hpp): format, units, the
  // turbine's range, channel locations, metadata against the signal, torque from the
  // wind when not recorded.
  app::recording::CheckedBundle bundle;
  try {
    bundle = app::recording::load_bundle(dir, {args.drivetrain});
  } catch (const app::recording::BundleCheckError& e) {
    throw CommandError(e.what());
  }
  if (!args.quiet)
    for (const auto& note : bundle.notes)
      std::fprintf(stderr, "diagnose: note: %s\n", note.c_str());
  const hal::Recording& rec = bundle.recording;
  const model::Drivetrain& drivetrain = bundle.drivetrain;
  const std::string samples_file = (dir / rec.samples_file).string();

  // The measurement points of the description, by channel name.
  md::DiagnosisInput in;
  in.sample_rate_hz = rec.sample_rate_hz;
  in.samples = rec.sample_count();
  if (drivetrain.measurement_points.size() < md::kPoints) {
    throw CommandError("drivetrain '" + drivetrain.name +
                       "': measurement_points: the diagnosis needs " + std::to_string(md::kPoints) +
                       ", found " + std::to_string(drivetrain.measurement_points.size()));
  }
  for (std::size_t p = 0; p < md::kPoints; ++p) {
    const model::MeasurementPoint& mp = drivetrain.measurement_points[p];
    const auto idx = rec.channel_index(mp.channel);
    if (!idx) {
      throw CommandError((dir / "recording.json").string() + ": channels: no channel named '" +
                         mp.channel + "' (measurement point at " + mp.location + ")");
    }
    in.points[p] = rec.samples[*idx].data();
  }
  // A tacho: its pulses, or a clear refusal.
  for (std::size_t c = 0; c < rec.channels.size(); ++c) {
    const hal::BundleChannel& ch = rec.channels[c];
    if (ch.kind != "once_per_rev") continue;
    model::dsp::OrderTracker tracker(1, 1, rec.samples[c].size());
    const std::size_t n =
        tracker.detect_pulses(rec.samples[c].data(), rec.samples[c].size(), rec.sample_rate_hz);
    if (n < 2) {
      throw CommandError(samples_file + ": channel '" + ch.name + "': tacho (once_per_rev on " +
                         ch.location + ") has " + std::to_string(n) + " pulse" +
                         (n == 1 ? "" : "s") + "; expected one rising edge per revolution");
    }
    in.tacho_pulses_s.assign(tracker.pulse_times(), tracker.pulse_times() + n);
    in.tacho_shaft = ch.location;
    break;
  }
  in.rotor_speed_rpm = rec.operating_point.rotor_speed_rpm;
  in.input_torque_nm = bundle.input_torque_nm;

  md::DiagnoserConfig cfg;
  cfg.calibration.trust_region.max_evaluations = args.evaluations;
  cfg.max_candidates = args.candidates;
  cfg.fit_evaluations = args.fit_evaluations;
  cfg.calibration.warm_rounds = !args.probe_every_round;
  md::RomEffectSimulator simulator(drivetrain, cfg.settle_s);
  md::Diagnoser diagnoser(drivetrain, simulator, cfg);
  const auto t0 = std::chrono::steady_clock::now();
  diagnoser.start(in);
  md::DiagnosisStep st;
  md::DiagnosisStage shown = md::DiagnosisStage::kIdle;
  static constexpr const char* kStageNames[] = {"idle",     "speed",  "analyse", "calibrate",
                                                "simulate", "locate", "refit",   "decide",
                                                "final",    "done"};
  while ((st = diagnoser.step()) == md::DiagnosisStep::kRunning) {
    if (!args.quiet && diagnoser.stage() != shown) {
      shown = diagnoser.stage();
      std::fprintf(stderr, "diagnose: %s (%.1f s)\n", kStageNames[static_cast<int>(shown)],
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const md::DiagnosisReport& r = diagnoser.report();
  if (st != md::DiagnosisStep::kFinished) {
    const std::string where =
        r.status == md::DiagnosisStatus::kTooShort || r.status == md::DiagnosisStatus::kBadInput
            ? samples_file
            : dir.string();
    throw CommandError(where + ": " + md::to_string(r.status) + ": " + r.message);
  }

  const std::string name = dir.filename().string().empty() ? dir.parent_path().filename().string()
                                                           : dir.filename().string();
  if (!args.quiet) {
    std::printf("bundle %s: %s, rotor %.3f rpm (speed from %s), torque %.0f N·m, %zu revolutions\n",
                name.c_str(), drivetrain.name.c_str(), r.rotor_speed_rpm, r.speed_source.c_str(),
                r.input_torque_nm, r.revolutions);
    std::printf("residual before %.3f, calibrated %.3f, after %.3f\n", r.residual_before,
                r.residual_calibrated, r.residual_after);
    for (std::size_t p = 0; p < md::kPoints; ++p) {
      std::printf(
          "  %s f1/f2/f3 before %.3f/%.3f/%.3f  calibrated %.3f/%.3f/%.3f  after %.3f/%.3f/%.3f\n",
          drivetrain.measurement_points[p].channel.c_str(), r.fit_before[p].f1, r.fit_before[p].f2,
          r.fit_before[p].f3, r.fit_calibrated[p].f1, r.fit_calibrated[p].f2,
          r.fit_calibrated[p].f3, r.fit_after[p].f1, r.fit_after[p].f2, r.fit_after[p].f3);
    }
    for (const md::MismatchEntry& m : r.mismatch)
      std::printf("mismatch %s %.1f-%.1f Hz: %s (share %.2f)\n", m.channel.c_str(), m.band_lo_hz,
                  m.band_hi_hz, m.signature.c_str(), m.share);
    for (std::size_t i = 0; i < r.ranking.size() && i < 8; ++i)
      std::printf(
          "ranked %zu: %s @ %s (%s), score %.3f\n", i + 1,
          md::effect_id(diagnoser.catalogue().hypotheses[r.ranking[i].hypothesis].effect),
          diagnoser.catalogue().hypotheses[r.ranking[i].hypothesis].location.c_str(),
          diagnoser.catalogue().hypotheses[r.ranking[i].hypothesis].domain == md::Domain::kEnvelope
              ? "envelope"
              : "spectrum",
          r.ranking[i].score);
    for (const md::CandidateResult& c : r.candidates)
      std::printf("candidate %s @ %s: score %.3f, confidence %.2f%s — %s\n",
                  md::effect_id(c.effect), c.location.c_str(), c.prior_score, c.confidence,
                  c.accepted ? " REPORTED" : "", c.verdict.c_str());
    if (r.missing.empty()) std::printf("missing physics: none\n");
    for (std::size_t i : r.missing)
      std::printf("missing physics: %s at %s (confidence %.2f)\n",
                  md::effect_id(r.candidates[i].effect), r.candidates[i].location.c_str(),
                  r.candidates[i].confidence);
    std::printf(
        "diagnosed in %.1f s (%zu model evaluations, %zu of them repeats not simulated again)\n",
        seconds, diagnoser.simulations(), simulator.repeats());
  }
  // Both reports are built before either is written: nothing is left half-written.
  std::string json_text, html_text;
  if (!args.json.empty())
    json_text = app::diagnosis::report_json(r, diagnoser.catalogue(), name).dump(2) + "\n";
  if (!args.html.empty()) html_text = app::diagnosis::report_html(r, diagnoser.catalogue(), name);
  if (!args.json.empty()) write_file(args.json, json_text);
  if (!args.html.empty()) write_file(args.html, html_text);
}

void setup(CLI::App& sub) {
  auto args = std::make_shared<Args>();
  sub.add_option("bundle", args->bundle, "Recording bundle directory (drivetwin-recording/1)")
      ->required();
  sub.add_option("--json", args->json,
                 "Write the diagnosis report (drivetwin-diagnosis/1) to this file");
  sub.add_option("--html", args->html, "Write the offline HTML report to this file");
  sub.add_option("--drivetrain", args->drivetrain, "Drivetrain NAME|FILE (default: the bundle's)");
  sub.add_option("--evaluations", args->evaluations,
                 "Calibration: fit evaluations per round, as `drivetwin calibrate --evaluations` "
                 "(default 30)")
      ->check(app::cli::integer_in(1, 100000, "model evaluations"));
  sub.add_option("--candidates", args->candidates, "Hypotheses modelled and refitted (default 3)")
      ->check(app::cli::integer_in(1, 20, "hypotheses"));
  sub.add_option("--fit-evaluations", args->fit_evaluations,
                 "Model evaluations per refitted hypothesis (default 10)")
      ->check(app::cli::integer_in(1, 10000, "model evaluations"));
  sub.add_flag("--probe-every-round", args->probe_every_round,
               "Calibration: probe every variable in every round, as `drivetwin calibrate "
               "--probe-every-round`");
  sub.add_flag("--quiet", args->quiet, "Print nothing but errors");
  sub.callback([args] { run(*args); });
}

}  // namespace diagnose_cmd

const bool kDiagnoseRegistered = app::cli::register_command(
    {"diagnose",
     "Locate the mismatch calibration cannot remove, name the missing physics, model it and refit",
     &diagnose_cmd::setup});

}  // namespace
