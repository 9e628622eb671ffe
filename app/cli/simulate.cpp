// `drivetwin simulate --rpm R --torque T --seconds S --out DIR [--full]`: runs the
// gearbox dynamics (model/dynamics: the reduced-order model the box runs, or the
// full-order reference with --full) at one operating point and writes
//   DIR/recording.json + DIR/cms.wav   a recording bundle (shared/reference/recording-bundle.md):
//                                      point1, point2 [m/s²] and a once-per-revolution
//                                      hss tacho [V], float32 WAV
//   DIR/loads.csv                      t_s, every mesh force [N] (line of action,
//                                      compression > 0) and bearing load [N] (x, y, radial)
// Host / start-up code: allocates, throws CommandError with the option or file named.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "cli/command.hpp"
#include "config/drivetrain_file.hpp"
#include "hal/recording_bundle.hpp"
#include "model/dynamics/simulate.hpp"

namespace {

namespace fs = std::filesystem;
using app::cli::CommandError;

struct SimulateArgs {
  std::string drivetrain;
  double rpm = 0.0;
  double torque_nm = -1.0;
  double seconds = 2.0;
  double sample_rate_hz = 25600.0;
  std::string out;
  bool full = false;
};

constexpr double kTachoHighV = 5.0;      // [V] pulse level
constexpr double kTachoPulseRev = 0.02;  // [rev] pulse width as a fraction of one hss revolution

void write_loads_csv(const fs::path& file, const model::dynamics::SimulationOutputs& o) {
  std::ofstream f(file);
  if (!f) throw CommandError(file.string() + ": cannot open for writing");
  f << "t_s";
  for (const auto& id : o.mesh_ids) f << ',' << id << "_n";
  for (const auto& id : o.bearing_ids)
    f << ',' << id << "_x_n," << id << "_y_n," << id << "_radial_n";
  f << '\n';
  char buf[64];
  const std::size_t n = o.hss_revolutions.size();
  for (std::size_t i = 0; i < n; ++i) {
    std::snprintf(buf, sizeof buf, "%.8f", static_cast<double>(i + 1) / o.sample_rate_hz);
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
  if (!(a.rpm > 0.0) || !std::isfinite(a.rpm))
    throw CommandError("--rpm: expected a finite value > 0 [rpm]");
  if (a.torque_nm < 0.0 || !std::isfinite(a.torque_nm))
    throw CommandError("--torque: expected a finite value ≥ 0 [N·m]");
  if (!(a.seconds > 0.0) || !(a.seconds <= 3600.0))
    throw CommandError("--seconds: expected a value in (0, 3600] [s]");
  if (!(a.sample_rate_hz > 0.0) || !std::isfinite(a.sample_rate_hz)) {
    throw CommandError("--rate: expected a finite value > 0 [Hz]");
  }
  const model::dynamics::OperatingPoint op{a.rpm, a.torque_nm};
  model::dynamics::SimulationSettings s;
  s.seconds = a.seconds;
  s.sample_rate_hz = a.sample_rate_hz;
  std::string error;
  if (!model::dynamics::check_simulation_inputs(op, s, &error)) throw CommandError(error);
  // The turbine's range: up to 20 % overspeed and 150 % of rated torque.
  hal::OperatingRange range;
  range.max_rotor_speed_rpm = 1.2 * d.turbine.rated_rotor_speed_rpm;
  range.max_input_torque_nm = 1.5 * d.turbine.rated_torque_nm;
  if (range.max_rotor_speed_rpm > 0.0 && a.rpm > range.max_rotor_speed_rpm) {
    throw CommandError("--rpm: " + std::to_string(a.rpm) + " rpm is above the turbine's range (≤ " +
                       std::to_string(range.max_rotor_speed_rpm) + " rpm, 120 % of rated)");
  }
  if (range.max_input_torque_nm > 0.0 && a.torque_nm > range.max_input_torque_nm) {
    throw CommandError("--torque: " + std::to_string(a.torque_nm) +
                       " N·m is above the turbine's range (≤ " +
                       std::to_string(range.max_input_torque_nm) + " N·m, 150 % of rated)");
  }

  model::dynamics::SimulationOutputs out;
  const bool ok = a.full ? model::dynamics::simulate_full(d, op, s, out, &error)
                         : model::dynamics::simulate_rom(d, op, s, out, &error);
  if (!ok) throw CommandError(error);

  hal::Recording rec;
  const bool builtin =
      a.drivetrain.find('/') == std::string::npos && a.drivetrain.find('.') == std::string::npos;
  rec.drivetrain = builtin ? a.drivetrain : "drivetrain.toml";
  rec.sample_rate_hz = a.sample_rate_hz;
  rec.samples_file = "cms.wav";
  for (std::size_t c = 0; c < out.sensor_channels.size(); ++c) {
    const model::MeasurementPoint& mp = d.measurement_points[c];
    rec.channels.push_back({mp.channel, mp.location, mp.direction, "", "m/s^2"});
    rec.samples.push_back(out.acceleration_m_s2[c]);
  }
  rec.channels.push_back({"tacho", "hss", "", "once_per_rev", "V"});
  std::vector<double> tacho(out.hss_revolutions.size());
  for (std::size_t i = 0; i < tacho.size(); ++i) {
    const double frac = out.hss_revolutions[i] - std::floor(out.hss_revolutions[i]);
    tacho[i] = frac < kTachoPulseRev ? kTachoHighV : 0.0;
  }
  rec.samples.push_back(std::move(tacho));
  rec.operating_point.rotor_speed_rpm = a.rpm;
  rec.operating_point.input_torque_nm = a.torque_nm;
  rec.notes = std::string("drivetwin simulate: ") +
              (a.full ? "full-order model (Newmark)" : "reduced-order model") + ", " +
              std::to_string(a.seconds) + " s from static equilibrium";
  const fs::path dir(a.out);
  if (const auto err = hal::write_bundle(dir, rec, range)) throw CommandError(err->to_string());
  if (!builtin) {
    std::ofstream f(dir / "drivetrain.toml");
    f << app::config::to_toml(d);
    if (!f) throw CommandError((dir / "drivetrain.toml").string() + ": write failed");
  }
  write_loads_csv(dir / "loads.csv", out);
  std::printf(
      "wrote %s (recording.json, cms.wav: point1, point2, tacho; loads.csv) — %zu samples at %.0f "
      "Hz, %s\n",
      dir.string().c_str(), out.hss_revolutions.size(), a.sample_rate_hz,
      a.full ? "full model" : "ROM");
}

void setup_simulate(CLI::App& sub) {
  auto args = std::make_shared<SimulateArgs>();
  app::config::add_drivetrain_option(sub, args->drivetrain);
  sub.add_option("--rpm", args->rpm, "Rotor speed [rpm]")->required();
  sub.add_option("--torque", args->torque_nm, "Rotor (gearbox input) torque [N·m]")->required();
  sub.add_option("--seconds", args->seconds, "Simulated time [s] (default 2)");
  sub.add_option("--rate", args->sample_rate_hz,
                 "Sample rate [Hz] (default 25600; the ROM steps at this rate)");
  sub.add_option("--out", args->out, "Output bundle directory")->required();
  sub.add_flag("--full", args->full,
               "Use the full-order reference model (slow) instead of the ROM");
  sub.callback([args] { run(*args); });
}

const bool kSimulateRegistered = app::cli::register_command(
    {"simulate", "Simulate the gearbox dynamics at one operating point into a recording bundle",
     &setup_simulate});

}  // namespace
