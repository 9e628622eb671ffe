// Demo stage "gearbox": the reference gearbox (paper-2mw) at the paper's operating
// point — wind 6.75 m/s, rotor 8.33 rpm — through the twin's own chain: the wind load
// model gives the input torque, the reduced-order dynamics model (the one the box
// runs) gives the dynamic mesh forces and the seat accelerations at the two CMS
// points. It prints what a gear engineer checks first: the mean mesh force of each
// stage against torque / base radius (hand statics), the fluctuation, and the
// strongest spectral lines at point1 and point2 named by the mesh harmonic they sit on.
// Host / command code: allocates, throws CommandError.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <numeric>
#include <string>
#include <vector>

#include "cli/run.hpp"
#include "demo/demo.hpp"
#include "model/drivetrain/description.hpp"
#include "model/drivetrain/kinematics.hpp"
#include "model/dsp/spectrum.hpp"
#include "model/dynamics/simulate.hpp"
#include "model/wind/wind_load.hpp"

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kPaperWindMps = 6.75;   // [m/s] the paper's check point
constexpr double kPaperRotorRpm = 8.33;  // [rpm]
constexpr double kSimSeconds = 2.0;      // [s]
constexpr std::size_t kFft = 32768;      // last 1.28 s at 25.6 kHz: 0.78 Hz lines

double cpu_seconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

// Torque → mean normal force per mesh (ISO 21771 geometry): F = T_gear / (n·r_b·cos β_b),
// r_b = z·m_n/(2 cos β)·cos α_t, tan α_t = tan α_n / cos β, tan β_b = tan β·cos α_t.
double mesh_force_n(const model::GearStage& st, int teeth, double torque_nm, int paths) {
  const double at = std::atan(std::tan(st.pressure_angle_rad) / std::cos(st.helix_angle_rad));
  const double bb = std::atan(std::tan(st.helix_angle_rad) * std::cos(at));
  const double rb =
      teeth * st.normal_module_m / (2.0 * std::cos(st.helix_angle_rad)) * std::cos(at);
  return torque_nm / (paths * rb * std::cos(bb));
}

struct Line {
  double hz = 0.0;
  double amplitude = 0.0;
};

// The strongest local maxima above 20 Hz, by Hann-lobe amplitude.
std::vector<Line> strongest_lines(const std::vector<double>& x, double fs, std::size_t count) {
  model::dsp::SpectrumAnalyzer fft(kFft);
  std::vector<double> spec(fft.lines());
  fft.amplitude_spectrum(x.data() + (x.size() - kFft), spec.data());
  const double df = fs / static_cast<double>(kFft);
  std::vector<Line> peaks;
  for (std::size_t k = static_cast<std::size_t>(20.0 / df); k + 1 < spec.size(); ++k) {
    if (spec[k] > spec[k - 1] && spec[k] >= spec[k + 1]) {
      peaks.push_back({static_cast<double>(k) * df,
                       fft.tone_amplitude(spec.data(), static_cast<double>(k), 2)});
    }
  }
  std::sort(peaks.begin(), peaks.end(),
            [](const Line& a, const Line& b) { return a.amplitude > b.amplitude; });
  if (peaks.size() > count) peaks.resize(count);
  return peaks;
}

// A line is named after the mesh harmonic it sits on (within two lines). Beyond the
// 10th harmonic the combs are dense (the planetary mesh's spacing is 13.7 Hz at this
// speed), so such a match is only "near" — there it may as well be a housing mode.
std::string name_line(double hz, const std::vector<std::pair<std::string, double>>& meshes,
                      double df) {
  for (const bool low_order : {true, false}) {
    for (const auto& [name, f] : meshes) {
      const double k = std::round(hz / f);
      if (k < 1.0 || (low_order && k > 10.0) || std::abs(hz - k * f) > 2.0 * df) continue;
      return std::string(low_order ? "" : "near ") + name + " mesh ×" +
             std::to_string(static_cast<int>(k));
    }
  }
  return "no mesh harmonic";
}

void run_gearbox_stage(const app::demo::DemoContext& ctx) {
  const auto d = model::builtin_drivetrain("paper-2mw");
  if (!d) throw app::cli::CommandError("demo: built-in drivetrain paper-2mw missing");
  const model::wind::WindLoad wind(d->turbine);
  const double omega = kPaperRotorRpm * 2.0 * kPi / 60.0;
  const model::wind::WindLoadOutput load = wind.with_rotor_speed(kPaperWindMps, omega, 0.0, false);
  std::fprintf(
      ctx.out,
      "paper-2mw at the paper's operating point: wind %.2f m/s, rotor %.2f rpm → input torque "
      "%.0f kN·m (wind load model; paper: 361.7)\n",
      kPaperWindMps, kPaperRotorRpm, load.torque_nm / 1e3);

  const model::dynamics::OperatingPoint op{kPaperRotorRpm, load.torque_nm};
  model::dynamics::SimulationSettings settings;
  settings.seconds = kSimSeconds;
  model::dynamics::SimulationOutputs out;
  std::string error;
  const double t0 = cpu_seconds();
  if (!model::dynamics::simulate_rom(*d, op, settings, out, &error)) {
    throw app::cli::CommandError("demo: gearbox: " + error);
  }
  const double cpu = cpu_seconds() - t0;
  std::fprintf(
      ctx.out,
      "reduced-order model: %.1f s simulated at %.0f Hz in %.2f s CPU, model build included "
      "(%.0f× real time)\n",
      kSimSeconds, settings.sample_rate_hz, cpu, cpu > 0.0 ? kSimSeconds / cpu : 0.0);

  // Hand statics: stage torques from the tooth counts (ring fixed, carrier in, sun out).
  const model::GearStage* pl = d->stage("planetary");
  const model::GearStage* im = d->stage("intermediate");
  const model::GearStage* hs = d->stage("high_speed");
  if (!pl || !im || !hs || pl->gears.size() < 3 || im->gears.size() < 2 || hs->gears.size() < 2) {
    throw app::cli::CommandError("demo: gearbox: paper-2mw lacks a stage");
  }
  const int zs = d->gear(pl->gears[0])->teeth, zr = d->gear(pl->gears[2])->teeth;
  const int z_im_pinion = d->gear(im->gears[1])->teeth, z_im_wheel = d->gear(im->gears[0])->teeth;
  const int z_hs_pinion = d->gear(hs->gears[1])->teeth;
  const double t_sun = load.torque_nm * zs / (zs + zr);
  const double t_ims = t_sun * z_im_pinion / z_im_wheel;
  const int planets = pl->planets;

  std::fprintf(ctx.out,
               "mesh force, last 1.28 s   mean [kN]  statics [kN]  RMS of fluctuation [kN]\n");
  for (std::size_t m = 0; m < out.mesh_ids.size(); ++m) {
    const auto& f = out.mesh_force_n[m];
    const auto first = f.end() - static_cast<std::ptrdiff_t>(kFft);
    const double mean = std::accumulate(first, f.end(), 0.0) / kFft;
    double var = 0.0;
    for (auto it = first; it != f.end(); ++it) var += (*it - mean) * (*it - mean);
    const std::string& id = out.mesh_ids[m];
    double expected = 0.0;
    if (id.rfind("sun_planet", 0) == 0) {
      expected = mesh_force_n(*pl, zs, t_sun, planets);
    } else if (id.rfind("ring_planet", 0) == 0) {
      expected = mesh_force_n(*pl, zr, load.torque_nm - t_sun, planets);
    } else if (id == "intermediate") {
      expected = mesh_force_n(*im, z_im_pinion, t_ims, 1);
    } else if (id == "high_speed") {
      expected =
          mesh_force_n(*hs, z_hs_pinion, t_ims * z_hs_pinion / d->gear(hs->gears[0])->teeth, 1);
    }
    std::fprintf(ctx.out, "  %-14s %10.1f %13.1f %18.2f\n", id.c_str(), mean / 1e3, expected / 1e3,
                 std::sqrt(var / kFft) / 1e3);
  }

  const model::Kinematics kin(*d);
  const std::vector<std::pair<std::string, double>> meshes = {
      {"high-speed", kin.mesh_hz(2, kPaperRotorRpm)},
      {"intermediate", kin.mesh_hz(1, kPaperRotorRpm)},
      {"planetary", kin.mesh_hz(0, kPaperRotorRpm)}};
  std::fprintf(ctx.out,
               "mesh frequencies: high-speed %.2f Hz, intermediate %.2f Hz, planetary %.3f Hz\n",
               meshes[0].second, meshes[1].second, meshes[2].second);
  const double df = settings.sample_rate_hz / static_cast<double>(kFft);
  for (std::size_t s = 0; s < out.sensor_channels.size(); ++s) {
    const auto& a = out.acceleration_m_s2[s];
    const double rms = model::dsp::rms(a.data() + (a.size() - kFft), kFft);
    std::fprintf(ctx.out,
                 "%s (%s seat): RMS %.3g m/s², strongest lines:", out.sensor_channels[s].c_str(),
                 d->measurement_points[s].location.c_str(), rms);
    for (const Line& l : strongest_lines(a, settings.sample_rate_hz, 4)) {
      std::fprintf(ctx.out, "  %.1f Hz %.3g m/s² (%s);", l.hz, l.amplitude,
                   name_line(l.hz, meshes, df).c_str());
    }
    std::fprintf(ctx.out, "\n");
  }
}

const bool kGearboxStageRegistered = app::demo::register_stage({20, "gearbox", &run_gearbox_stage});

}  // namespace
