// `drivetwin simulate --rpm R --torque T --seconds S --out DIR [--full]`: runs the
// gearbox dynamics (model/dynamics: the reduced-order model the box runs, or the
// full-order reference with --full) at one operating point and writes
//   DIR/recording.json + DIR/cms.wav   a recording bundle (shared/reference/recording-bundle.md):
//                                      point1, point2 [m/s²] and a once-per-revolution
//                                      hss tacho [V], float32 WAV
//   DIR/loads.csv                      t_s, every mesh force [N] (line of action,
//                                      compression > 0) and bearing load [N] (x, y, radial);
//                                      every --loads-every'th sample, or none (--no-loads)
//
// Run-in: the models start from the static deflection under the mean stiffness, and the
// start-up transient is not part of the steady vibration a CMS records at that operating
// point (it doubles point2's RMS of a 2 s run). The first --run-in seconds are simulated
// and discarded; by default ("auto") ln(100)·2/η: with Rayleigh damping C = ηM + ζK the
// modal decay rate is (η + ζω²)/2 ≥ η/2, so after that time every mode's free response
// is below 1 % of its start (bounded to 0.5–10 s; 10 s when η = 0). The recording starts
// after it (t = 0, tacho phase continuing); the command says what it discarded.
//
// Sample rate: the ROM steps at --rate and interpolates its forces linearly over a step,
// which scales a line at f by sinc²(π·f/rate) (model/dynamics/rom.hpp). A rate below
// 6 × the high-speed mesh frequency (≥ 9 % lost on the mesh line, its harmonics aliased)
// or below 2.56 × the ROM's mode cut-off (modes above Nyquist) is refused.
//
// Host / start-up code: allocates, throws CommandError with the option or file named.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "cli/command.hpp"
#include "cli/options.hpp"
#include "cli/sample_rate_check.hpp"
#include "config/drivetrain_file.hpp"
#include "fatigue/progress.hpp"
#include "hal/recording_bundle.hpp"
#include "model/drivetrain/kinematics.hpp"
#include "model/dynamics/simulate.hpp"
#include "recording/bundle_check.hpp"

namespace {

namespace fs = std::filesystem;
using app::cli::CommandError;

struct SimulateArgs {
  std::string drivetrain;
  double rpm = 0.0;
  double torque_nm = -1.0;
  double seconds = 2.0;
  double sample_rate_hz = 25600.0;
  double run_in_s = -1.0;  // [s] < 0: auto
  std::size_t loads_every = 1;
  bool no_loads = false;
  bool no_progress = false;
  std::string out;
  bool full = false;
};

constexpr double kRunInMinS = 0.5;        // [s]
constexpr double kRunInMaxS = 10.0;       // [s]
constexpr double kRunInDecay = 4.60517;   // [-] ln(100): free response down to 1 %
constexpr double kMeshRateFactor = 6.0;   // [-] rate / high-speed mesh frequency
constexpr double kModeRateFactor = 2.56;  // [-] rate / ROM mode cut-off

constexpr double kTachoHighV = 5.0;      // [V] pulse level
constexpr double kTachoPulseRev = 0.02;  // [rev] pulse width as a fraction of one hss revolution

void write_loads_csv(const fs::path& file, const model::dynamics::SimulationOutputs& o,
                     std::size_t first, std::size_t every) {
  std::ofstream f(file);
  if (!f) throw CommandError(file.string() + ": cannot open for writing");
  f << "t_s";
  for (const auto& id : o.mesh_ids) f << ',' << id << "_n";
  for (const auto& id : o.bearing_ids)
    f << ',' << id << "_x_n," << id << "_y_n," << id << "_radial_n";
  f << '\n';
  char buf[64];
  const std::size_t n = o.hss_revolutions.size();
  for (std::size_t i = first; i < n; i += every) {
    std::snprintf(buf, sizeof buf, "%.8f", static_cast<double>(i + 1 - first) / o.sample_rate_hz);
    f << buf;
    for (const auto& m : o.mesh_force_n) {
      std::snprintf(buf, sizeof buf, ",%.6g", m[i]);
      f << buf;
    }
    for (std::size_t b = 0; b < o.bearing_ids.size(); ++b) {
      const double x = o.bearing_force_x_n[b][i];
      const double y = o.bearing_force_y_n[b][i];
      std::snprintf(buf, sizeof buf, ",%.6g,%.6g,%.6g", x, y, std::hypot(x, y));
      f << buf;
    }
    f << '\n';
  }
  if (!f) throw CommandError(file.string() + ": write failed");
}

void run(const SimulateArgs& a) {
  model::Drivetrain d;
  try {
    d = app::config::load_drivetrain(a.drivetrain);
  } catch (const std::exception& e) {
    throw CommandError(std::string("--drivetrain: ") + e.what());
  }
  // The turbine's range (app/recording/bundle_check.hpp): what a recording may hold.
  const hal::OperatingRange range = app::recording::operating_range(d);
  if (range.max_rotor_speed_rpm > 0.0 && a.rpm > range.max_rotor_speed_rpm) {
    throw CommandError("--rpm: " + std::to_string(a.rpm) + " rpm is above the turbine's range (≤ " +
                       std::to_string(range.max_rotor_speed_rpm) + " rpm, 120 % of rated)");
  }
  if (range.max_input_torque_nm > 0.0 && a.torque_nm > range.max_input_torque_nm) {
    throw CommandError("--torque: " + std::to_string(a.torque_nm) +
                       " N·m is above the turbine's range (≤ " +
                       std::to_string(range.max_input_torque_nm) + " N·m, 150 % of rated)");
  }
  // The sample rate against the fastest mesh line and the ROM's modes.
  model::dynamics::SimulationSettings s;
  app::cli::SampleRateNeeds needs;
  needs.mesh_factor = kMeshRateFactor;
  needs.mode_factor = kModeRateFactor;
  needs.mesh_why = "6x: the ROM's force interpolation loses <= 9 %, harmonics not aliased";
  const std::string rate_error = app::cli::check_sample_rate("--rate", a.sample_rate_hz, d, a.rpm,
                                                             s.rom_cutoff_hz, nullptr, needs);
  if (!rate_error.empty()) throw CommandError(rate_error);
  // Run-in: auto from the damping (see the file comment).
  double run_in = a.run_in_s;
  std::string run_in_why;
  if (run_in < 0.0) {
    const double eta = d.dynamics.rayleigh_eta;
    run_in = eta > 0.0 ? std::clamp(kRunInDecay * 2.0 / eta, kRunInMinS, kRunInMaxS) : kRunInMaxS;
    char text[200];
    if (eta > 0.0) {
      std::snprintf(text, sizeof text,
                    "auto: every mode's free response below 1 %% after ln(100)*2/eta = %.2f s "
                    "(eta = %g 1/s)",
                    kRunInDecay * 2.0 / eta, eta);
    } else {
      std::snprintf(text, sizeof text,
                    "auto: the description has no mass-proportional damping (eta = 0), so no "
                    "decay bound; %.0f s, the longest run-in",
                    kRunInMaxS);
    }
    run_in_why = text;
  } else {
    run_in_why = "--run-in";
  }
  const std::size_t first = static_cast<std::size_t>(std::llround(run_in * a.sample_rate_hz));
  const model::dynamics::OperatingPoint op{a.rpm, a.torque_nm};
  s.seconds = a.seconds + static_cast<double>(first) / a.sample_rate_hz;
  s.sample_rate_hz = a.sample_rate_hz;
  std::string error;
  if (!model::dynamics::check_simulation_inputs(op, s, &error)) throw CommandError(error);

  model::dynamics::SimulationOutputs out;
  bool ok = false;
  {
    // The full model runs about a minute (the ROM seconds): the time so far, on a terminal.
    char label[96];
    std::snprintf(label, sizeof label, "simulating %.2f s with the %s model", s.seconds,
                  a.full ? "full-order" : "reduced-order");
    const app::fatigue::ElapsedTicker ticker(
        app::fatigue::show_progress(a.no_progress, STDERR_FILENO), label);
    ok = a.full ? model::dynamics::simulate_full(d, op, s, out, &error)
                : model::dynamics::simulate_rom(d, op, s, out, &error);
  }
  if (!ok) throw CommandError(error);
  const std::size_t total = out.hss_revolutions.size();
  if (first >= total) throw CommandError("simulation returned no samples after the run-in");

  hal::Recording rec;
  const bool builtin =
      a.drivetrain.find('/') == std::string::npos && a.drivetrain.find('.') == std::string::npos;
  rec.drivetrain = builtin ? a.drivetrain : "drivetrain.toml";
  rec.sample_rate_hz = a.sample_rate_hz;
  rec.samples_file = "cms.wav";
  const auto kept = [&](const std::vector<double>& v) {
    return std::vector<double>(v.begin() + static_cast<std::ptrdiff_t>(first), v.end());
  };
  for (std::size_t c = 0; c < out.sensor_channels.size(); ++c) {
    const model::MeasurementPoint& mp = d.measurement_points[c];
    rec.channels.push_back({mp.channel, mp.location, mp.direction, "", "m/s^2"});
    rec.samples.push_back(kept(out.acceleration_m_s2[c]));
  }
  rec.channels.push_back({"tacho", "hss", "", "once_per_rev", "V"});
  std::vector<double> tacho(total - first);
  for (std::size_t i = 0; i < tacho.size(); ++i) {
    const double rev = out.hss_revolutions[first + i];
    tacho[i] = rev - std::floor(rev) < kTachoPulseRev ? kTachoHighV : 0.0;
  }
  rec.samples.push_back(std::move(tacho));
  rec.operating_point.rotor_speed_rpm = a.rpm;
  rec.operating_point.input_torque_nm = a.torque_nm;
  char notes[300];
  std::snprintf(notes, sizeof notes,
                "drivetwin simulate: %s, %g s after a run-in of %g s from static equilibrium "
                "(%s)",
                a.full ? "full-order model (Newmark)" : "reduced-order model", a.seconds,
                static_cast<double>(first) / a.sample_rate_hz, run_in_why.c_str());
  rec.notes = notes;
  const fs::path dir(a.out);
  if (const auto err = hal::write_bundle(dir, rec, range)) throw CommandError(err->to_string());
  if (!builtin) {
    std::ofstream f(dir / "drivetrain.toml");
    f << app::config::to_toml(d);
    if (!f) throw CommandError((dir / "drivetrain.toml").string() + ": write failed");
  }
  if (!a.no_loads) write_loads_csv(dir / "loads.csv", out, first, a.loads_every);
  std::printf(
      "wrote %s (recording.json, cms.wav: point1, point2, tacho%s) — %zu samples at %.0f "
      "Hz, %s\n",
      dir.string().c_str(), a.no_loads ? "" : "; loads.csv", total - first, a.sample_rate_hz,
      a.full ? "full model" : "ROM");
  std::printf("run-in: the first %g s (%zu samples) simulated and discarded (%s)\n",
              static_cast<double>(first) / a.sample_rate_hz, first, run_in_why.c_str());
  if (!a.no_loads && a.loads_every > 1) {
    std::printf("loads.csv: every %zu-th sample (%.0f Hz; content above %.0f Hz aliases)\n",
                a.loads_every, a.sample_rate_hz / static_cast<double>(a.loads_every),
                0.5 * a.sample_rate_hz / static_cast<double>(a.loads_every));
  }
  // Settled? The RMS of the first and last quarter of what was kept.
  for (std::size_t c = 0; c < out.sensor_channels.size(); ++c) {
    const std::vector<double>& x = rec.samples[c];
    const std::size_t q = x.size() / 4;
    if (q < 64) break;
    auto rms = [&](std::size_t from) {
      double m = 0.0, e = 0.0;
      for (std::size_t i = from; i < from + q; ++i) m += x[i];
      m /= static_cast<double>(q);
      for (std::size_t i = from; i < from + q; ++i) e += (x[i] - m) * (x[i] - m);
      return std::sqrt(e / static_cast<double>(q));
    };
    const double r0 = rms(0), r1 = rms(x.size() - q);
    if (r1 > 0.0 && std::fabs(r0 / r1 - 1.0) > 0.25) {
      std::fprintf(stderr,
                   "simulate: note: %s: the RMS of the first quarter is %.3g m/s^2, of the last "
                   "%.3g: not settled after the run-in? (--run-in S to lengthen it)\n",
                   out.sensor_channels[c].c_str(), r0, r1);
    }
  }
}

void setup_simulate(CLI::App& sub) {
  using app::cli::number_in;
  auto args = std::make_shared<SimulateArgs>();
  app::config::add_drivetrain_option(sub, args->drivetrain);
  sub.add_option("--rpm", args->rpm, "Rotor speed [rpm]")
      ->required()
      ->check(app::cli::positive("rpm"));
  sub.add_option("--torque", args->torque_nm, "Rotor (gearbox input) torque [N·m]")
      ->required()
      ->check(app::cli::non_negative("N·m"));
  sub.add_option("--seconds", args->seconds, "Simulated time kept [s] (default 2)")
      ->check(number_in(0.0, 3600.0, "s", true));
  sub.add_option("--rate", args->sample_rate_hz,
                 "Sample rate [Hz] (default 25600; the ROM steps at this rate; refused below "
                 "6x the high-speed mesh frequency or 2.56x the ROM's mode cut-off)")
      ->check(app::cli::positive("Hz"));
  sub.add_option("--run-in", args->run_in_s,
                 "Start-up transient simulated and discarded [s] (default: ln(100)*2/eta from "
                 "the description's damping, 0.5-10 s; 0 keeps the transient)")
      ->check(number_in(0.0, 600.0, "s"));
  sub.add_option("--loads-every", args->loads_every,
                 "Write every N-th sample to loads.csv (default 1: ~5 MB per simulated second)")
      ->check(app::cli::integer_in(1, 1000000));
  sub.add_flag("--no-loads", args->no_loads, "Write no loads.csv");
  sub.add_flag("--no-progress", args->no_progress, "No progress line on a terminal");
  sub.add_option("--out", args->out, "Output bundle directory")->required();
  sub.add_flag("--full", args->full,
               "Use the full-order reference model (slow) instead of the ROM");
  sub.callback([args] { run(*args); });
}

const bool kSimulateRegistered = app::cli::register_command(
    {"simulate", "Simulate the gearbox dynamics at one operating point into a recording bundle",
     &setup_simulate});

}  // namespace
