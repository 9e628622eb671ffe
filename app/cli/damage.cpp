// `drivetwin damage <scada.csv>`: history mode of the fatigue model. Years of SCADA rows
// → Palmgren–Miner damage per gear, failure mode and bearing, and remaining useful life,
// by interpolating a load spectrum per operating point (app/fatigue/damage_history.hpp).
// The spectrum is built once per drivetrain, rating options and grid, and cached in a
// file named by a hash of all of them.
//
// Load spectrum source: `--spectrum dynamics` runs the dynamics model's ROM per grid point
// (app/fatigue/dynamics_spectrum.hpp); `--spectrum quasi-static` is the named FALLBACK
// (mean mesh forces, model/fatigue/load_spectrum.hpp). Every output names the source.
#include <unistd.h>
#include <nlohmann/json.hpp>

#include <map>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli/command.hpp"
#include "cli/options.hpp"
#include "cli/sample_rate_check.hpp"
#include "config/drivetrain_checks.hpp"
#include "config/drivetrain_file.hpp"
#include "data/embedded.hpp"
#include "fatigue/bearing_report.hpp"
#include "fatigue/damage_history.hpp"
#include "fatigue/dynamics_spectrum.hpp"
#include "fatigue/progress.hpp"
#include "fatigue/spectrum_cache.hpp"
#include "hal/scada_csv.hpp"
#include "model/fatigue/drivetrain_channels.hpp"
#include "model/fatigue/load_spectrum.hpp"
#include "recording/bundle_check.hpp"

namespace {

namespace mf = model::fatigue;
namespace fs = std::filesystem;
using app::cli::CommandError;

constexpr double kYearS = 365.25 * 86400.0;

struct DamageArgs {
  std::string file;
  std::string drivetrain;
  std::string columns = "auto";
  std::string torque_from = "auto";
  bool bench = false;
  std::string json;
  std::string spectrum = "quasi-static";
  double rom_rate_hz = app::fatigue::DynamicsSpectrumSettings{}.sample_rate_hz;
  double rom_cutoff_hz = app::fatigue::DynamicsSpectrumSettings{}.rom_cutoff_hz;
  std::string cache_dir;
  std::string sn = "haibach";
  double period_s = 0.0;
  double k_a = 1.0;
  double k_h_beta = 0.0;  // 0: ISO 6336-1 method C
  std::string lead = "helix";
  std::string contact_pattern = "unverified";
  double f_ma_factor = 1.0;
  double pinion_offset = 0.25;
  int accuracy_grade = 6;
  model::fatigue::Lubrication lubrication{};  // ISO 281 a_ISO inputs (defaults: bearing_life.hpp)
  bool basic_life = false;
  bool no_progress = false;
  bool no_cache = false;
  bool per_day = false;
  std::string per_day_csv;
};

constexpr double kPaperDayDamage = 1.023e-5;  // [-] paper: sun contact damage of its one day
constexpr double kPaperWindMps = 6.75;        // [m/s] paper's operating point (daily mean)
constexpr std::size_t kNearestDays = 5;
constexpr double kPaperWindBandMps = 0.1;  // [m/s] days counted as "at the paper's check point"

std::string utc_date(long long day) {
  const std::time_t t = static_cast<std::time_t>(day) * 86400;
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[16];
  std::strftime(buf, sizeof buf, "%Y-%m-%d", &tm);
  return buf;
}

// "builtin:NAME" reads an embedded data file (app/data/NAME) through a temporary copy.
std::string resolve_input(const std::string& file, std::string& temp_path) {
  const std::string prefix = "builtin:";
  if (file.rfind(prefix, 0) != 0) return file;
  const std::string name = file.substr(prefix.size());
  const auto text = app::data::embedded_file(name);
  if (!text) {
    std::string names;
    for (const auto& n : app::data::embedded_file_names()) names += (names.empty() ? "" : ", ") + n;
    throw CommandError("'" + file + "': no embedded data file '" + name + "' (have: " + names +
                       ")");
  }
  std::string tmpl = (fs::temp_directory_path() / "drivetwin-damage-XXXXXX").string();
  const int fd = mkstemp(tmpl.data());
  if (fd < 0) throw CommandError("cannot create a temporary file for " + file);
  const ssize_t written = ::write(fd, text->data(), text->size());
  ::close(fd);
  if (written != static_cast<ssize_t>(text->size()))
    throw CommandError("cannot write a temporary copy of " + file);
  temp_path = tmpl;
  return tmpl;
}

double estimate_rows(const std::string& path) {
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  if (ec) return 0.0;
  std::ifstream in(path);
  std::string line;
  double bytes = 0.0, lines = 0.0;
  while (lines < 200 && std::getline(in, line)) {
    bytes += static_cast<double>(line.size() + 1);
    lines += 1.0;
  }
  return lines > 1 ? static_cast<double>(size) / (bytes / lines) : 0.0;
}

// A row time as a UTC date-time when it is one (after 1990), else in seconds.
std::string time_text(double t_s) {
  if (!std::isfinite(t_s)) return "?";
  if (t_s < 631152000.0) return "t_s = " + std::to_string(t_s) + " s";
  const std::time_t t = static_cast<std::time_t>(t_s);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[40];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S UTC", &tm);
  return buf;
}

nlohmann::json num(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

nlohmann::json quantiles_json(const app::fatigue::Quantiles& q) {
  return {{"min", q.min}, {"q1", q.q1},   {"median", q.median},
          {"q3", q.q3},   {"max", q.max}, {"mean", q.mean}};
}

void run(const DamageArgs& args) {
  const auto t0 = std::chrono::steady_clock::now();
  const model::Drivetrain drivetrain = app::config::load_drivetrain(args.drivetrain);
  std::string error;
  const bool auto_columns = args.columns == "auto";
  const auto columns = hal::parse_scada_columns(auto_columns ? "bundle" : args.columns, &error);
  if (!columns) throw CommandError("--columns: " + error);
  app::fatigue::TorqueFrom torque_from = app::fatigue::TorqueFrom::kAuto;
  if (args.torque_from == "torque") {
    torque_from = app::fatigue::TorqueFrom::kTorque;
  } else if (args.torque_from == "power") {
    torque_from = app::fatigue::TorqueFrom::kPower;
  } else if (args.torque_from == "wind") {
    torque_from = app::fatigue::TorqueFrom::kWind;
  } else if (args.torque_from == "wind-steady") {
    torque_from = app::fatigue::TorqueFrom::kWindSteady;
  } else if (args.torque_from != "auto") {
    throw CommandError("--torque-from: '" + args.torque_from +
                       "' is not one of auto, torque, power, wind, wind-steady");
  }
  mf::ChannelOptions options;
  options.k_a = args.k_a;
  options.rating.k_h_beta_override = args.k_h_beta;
  const auto lead = mf::parse_lead_modification(args.lead);
  if (!lead) {
    throw CommandError("--lead: '" + args.lead +
                       "' is not one of none, helix, helix-crowning, crowning, end-relief");
  }
  options.rating.face_load.lead = *lead;
  options.rating.face_load.f_ma_factor = args.f_ma_factor;
  if (args.contact_pattern != "unverified" && args.contact_pattern != "verified") {
    throw CommandError("--contact-pattern: '" + args.contact_pattern +
                       "' is not one of unverified, verified");
  }
  options.rating.face_load.contact_pattern_verified = args.contact_pattern == "verified";
  options.rating.face_load.pinion_offset_ratio = args.pinion_offset;
  options.rating.accuracy_grade = args.accuracy_grade;
  options.lubrication = args.lubrication;
  options.lubrication.enabled = !args.basic_life;
  if (!(args.lubrication.viscosity_100c_mm2_s < args.lubrication.viscosity_40c_mm2_s)) {
    throw CommandError(
        "--oil-viscosity-100: " + std::to_string(args.lubrication.viscosity_100c_mm2_s) +
        " mm2/s is not below --oil-viscosity-40 (" +
        std::to_string(args.lubrication.viscosity_40c_mm2_s) + " mm2/s): an oil thins as it warms");
  }
  if (args.sn == "haibach") {
    options.branch = mf::KneeBranch::kHaibach;
  } else if (args.sn == "iso") {
    options.branch = mf::KneeBranch::kIsoLifeLine;
  } else {
    throw CommandError("--sn: '" + args.sn + "' is not one of haibach, iso");
  }
  if (!(args.k_a >= 1.0)) throw CommandError("--k-a must be ≥ 1");
  if (!(args.k_h_beta == 0.0 || args.k_h_beta >= 1.0))
    throw CommandError("--k-h-beta must be ≥ 1 (or 0: method C)");
  if (!(args.f_ma_factor >= 0.0 && args.f_ma_factor <= 1.0))
    throw CommandError("--f-ma must be in [0, 1]");
  if (!(args.pinion_offset >= 0.0 && args.pinion_offset < 0.5))
    throw CommandError("--pinion-offset must be in [0, 0.5)");
  if (args.spectrum != "quasi-static" && args.spectrum != "dynamics" &&
      args.spectrum != "dynamics-rows") {
    throw CommandError("--spectrum: '" + args.spectrum +
                       "' is not one of dynamics, dynamics-rows, quasi-static");
  }
  // dynamics-rows: the dynamics model at every row's own operating point (no grid).
  const bool rows_mode = args.spectrum == "dynamics-rows";
  const mf::SpectrumSource source = args.spectrum != "quasi-static"
                                        ? mf::SpectrumSource::kDynamics
                                        : mf::SpectrumSource::kQuasiStatic;

  const mf::ChannelSet channels(drivetrain, options);
  if (!channels.valid())
    throw CommandError("drivetrain '" + drivetrain.name + "': " + channels.error());

  const mf::SpectrumGrid grid = source == mf::SpectrumSource::kDynamics
                                    ? app::fatigue::dynamics_grid(drivetrain)
                                    : app::fatigue::quasi_static_grid(drivetrain);
  if (!(grid.torque_max_nm > 0.0))
    throw CommandError("drivetrain '" + drivetrain.name + "': turbine.rated_torque_nm must be > 0");
  app::fatigue::DynamicsSpectrumSettings dynamics_settings;
  const bool default_rom = args.rom_rate_hz == dynamics_settings.sample_rate_hz &&
                           args.rom_cutoff_hz == dynamics_settings.rom_cutoff_hz;
  dynamics_settings.sample_rate_hz = args.rom_rate_hz;
  dynamics_settings.rom_cutoff_hz = args.rom_cutoff_hz;
  if (source == mf::SpectrumSource::kDynamics) {
    // The ROM's rate against this turbine's mesh lines up to its overspeed and the modes kept.
    const double max_rpm = std::max(
        grid.speed_max_rpm, app::recording::operating_range(drivetrain).max_rotor_speed_rpm);
    const std::string rate_error = app::cli::check_sample_rate(
        "--rom-rate", args.rom_rate_hz, drivetrain, max_rpm, args.rom_cutoff_hz, "--rom-cutoff");
    if (!rate_error.empty()) throw CommandError(rate_error);
  }
  const std::uint64_t key = app::fatigue::spectrum_key(
      drivetrain, channels, grid, source, app::fatigue::kSpectrumCodeVersion,
      default_rom || source != mf::SpectrumSource::kDynamics ? 0.0 : args.rom_rate_hz,
      default_rom || source != mf::SpectrumSource::kDynamics ? 0.0 : args.rom_cutoff_hz);
  const fs::path cache_dir = args.cache_dir.empty() ? app::fatigue::default_spectrum_cache_dir()
                                                    : fs::path(args.cache_dir);
  const fs::path cache_file = app::fatigue::spectrum_cache_file(cache_dir, key);
  // The SCADA file before the spectrum (minutes for a dynamics one): a missing or
  // unreadable file is said at once.
  std::string temp;
  const std::string path = resolve_input(args.file, temp);
  struct TempGuard {
    std::string p;
    ~TempGuard() {
      if (!p.empty()) std::remove(p.c_str());
    }
  } guard{temp};
  // --columns auto: the bundle's names, else the Kelmarsh export's.
  auto open_reader = [&](hal::ScadaCsvReader& r) {
    if (r.open(path, *columns)) return;
    const std::string first_error = r.error();
    if (auto_columns && r.open(path, hal::kelmarsh_scada_columns())) return;
    throw CommandError(first_error +
                       (auto_columns ? " (nor the Kelmarsh export's columns; see --columns)" : ""));
  };
  hal::ScadaCsvReader reader;
  open_reader(reader);

  mf::LoadSpectrum spectrum;
  spectrum.grid = grid;
  spectrum.source = source;
  bool cache_hit =
      !rows_mode && !args.no_cache &&
      app::fatigue::load_cached_spectrum(cache_file, key, channels.channel_count(), spectrum);
  std::string rows_sim_error;
  const mf::LoadSimulator rows_simulator =
      rows_mode ? app::fatigue::dynamics_simulator(drivetrain, channels, dynamics_settings,
                                                   &rows_sim_error)
                : mf::LoadSimulator{};
  if (!cache_hit && !rows_mode) {
    std::string sim_error;
    const mf::LoadSimulator simulator =
        source == mf::SpectrumSource::kDynamics
            ? app::fatigue::dynamics_simulator(drivetrain, channels, dynamics_settings, &sim_error)
            : mf::quasi_static_simulator(channels);
    // The dynamics spectrum runs the ROM at every grid point (minutes): a progress line on
    // a terminal, counted by wrapping the simulator.
    const double points = static_cast<double>(grid.torque_points) * grid.speed_points;
    app::fatigue::ProgressLine progress(
        source == mf::SpectrumSource::kDynamics &&
            app::fatigue::show_progress(args.no_progress, STDERR_FILENO),
        "load spectrum (dynamics model, cached afterwards)", "points", points);
    double simulated = 0.0;
    const mf::LoadSimulator counted = [&](double torque_nm, double rotor_rpm,
                                          mf::LoadSeries& series) {
      const bool ok = simulator(torque_nm, rotor_rpm, series);
      progress.update(++simulated);
      return ok;
    };
    spectrum = mf::build_load_spectrum(channels, grid, source, counted, &error);
    progress.finish();
    if (spectrum.channel_count == 0)
      throw CommandError(error + (sim_error.empty() ? "" : ": " + sim_error));
    if (!args.no_cache) (void)app::fatigue::store_cached_spectrum(cache_file, key, spectrum);
  }
  if (!rows_mode) spectrum.prepare();
  const auto t1 = std::chrono::steady_clock::now();

  // --bench: a reading-only pass over the same file first, as the baseline of the ratio.
  double read_only_s = 0.0, read_only_cpu_s = 0.0;
  if (args.bench) {
    hal::ScadaCsvReader base;
    open_reader(base);
    hal::ScadaRow row;
    std::size_t n = 0;
    const auto b0 = std::chrono::steady_clock::now();
    const std::clock_t c0 = std::clock();
    while (base.next(row) != hal::ScadaReadResult::kEnd) ++n;
    read_only_cpu_s = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
    read_only_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - b0).count();
    (void)n;
  }

  app::fatigue::HistoryOptions hopt;
  // Rows mode: one simulation per distinct operating point, remembered (a SCADA export
  // repeats points only when values repeat exactly).
  std::map<std::pair<double, double>, std::vector<double>> rows_cache;
  if (rows_mode) {
    hopt.at_point = [&](double torque_nm, double rotor_rpm, double* out) {
      auto it = rows_cache.find({torque_nm, rotor_rpm});
      if (it == rows_cache.end()) {
        std::vector<double> d(channels.channel_count());
        std::string why;
        if (!mf::damage_per_rev_at_point(channels, rows_simulator, torque_nm, rotor_rpm, d.data(),
                                         &why))
          throw std::runtime_error(why + (rows_sim_error.empty() ? "" : ": " + rows_sim_error));
        it = rows_cache.emplace(std::make_pair(torque_nm, rotor_rpm), std::move(d)).first;
      }
      std::copy(it->second.begin(), it->second.end(), out);
      return true;
    };
  }
  hopt.period_s = args.period_s;
  hopt.torque_from = torque_from;
  hopt.per_day = args.per_day || !args.per_day_csv.empty();
  const bool tty = app::fatigue::show_progress(args.no_progress, STDERR_FILENO);
  const double total_rows = tty ? estimate_rows(path) : 0.0;
  if (tty) {
    hopt.progress = [total_rows](std::size_t rows) {
      const double f = total_rows > 0 ? std::min(1.0, static_cast<double>(rows) / total_rows) : 0.0;
      const int width = 40, filled = static_cast<int>(f * width);
      std::fprintf(stderr, "\r[%.*s%*s] %5.1f %% %zu rows", filled,
                   "########################################", width - filled, "", 100.0 * f, rows);
    };
  }
  app::fatigue::HistoryResult h;
  const auto t1b = std::chrono::steady_clock::now();
  const std::clock_t cpu0 = std::clock();
  try {
    h = app::fatigue::run_history(reader, drivetrain, channels, spectrum, hopt);
  } catch (const std::runtime_error& e) {
    if (tty) std::fprintf(stderr, "\n");
    throw CommandError(e.what());
  }
  const auto t2 = std::chrono::steady_clock::now();
  const double rows_cpu_s = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
  if (tty) std::fprintf(stderr, "\r%*s\r", 70, "");
  const double spectrum_s = std::chrono::duration<double>(t1 - t0).count();
  const double rows_s = std::chrono::duration<double>(t2 - t1b).count();
  const double days = h.covered_s / 86400.0;

  for (const auto& i : h.issues) std::fprintf(stderr, "drivetwin damage: %s\n", i.message.c_str());
  if (h.rows_rejected + h.gaps > h.issues.size()) {
    std::fprintf(stderr, "drivetwin damage: ... %zu more issues not listed (counts below)\n",
                 h.rows_rejected + h.gaps - h.issues.size());
  }

  const char* src = mf::spectrum_source_name(spectrum.source);
  std::printf("# drivetwin damage %s (drivetrain %s)\n", args.file.c_str(),
              drivetrain.name.c_str());
  if (rows_mode) {
    std::printf(
        "# load spectrum: dynamics-rows — the ROM at every row's own (torque, speed), %zu "
        "simulations at %.0f Hz (cut-off %.0f Hz), no interpolation "
        "(app/fatigue/dynamics_spectrum.hpp), damping eta = %g 1/s, zeta = %g s; K_A = %.2f, "
        "K_v = 1\n",
        rows_cache.size(), args.rom_rate_hz, args.rom_cutoff_hz, drivetrain.dynamics.rayleigh_eta,
        drivetrain.dynamics.rayleigh_zeta, args.k_a);
  } else if (source == mf::SpectrumSource::kDynamics) {
    std::printf(
        "# load spectrum: %s — ROM mesh forces and bearing reactions per (torque, speed) point "
        "(app/fatigue/dynamics_spectrum.hpp), damping eta = %g 1/s, zeta = %g s; K_A = %.2f, K_v = "
        "1; %s %s\n",
        src, drivetrain.dynamics.rayleigh_eta, drivetrain.dynamics.rayleigh_zeta, args.k_a,
        cache_hit ? "cache hit" : "built, cached as", cache_hit ? "" : cache_file.string().c_str());
  } else {
    std::printf(
        "# load spectrum: %s — mean mesh force from torque, equal planet sharing, K_A = %.2f, "
        "K_v = 1, no dynamic content; %s %s\n",
        src, args.k_a, cache_hit ? "cache hit" : "built, cached as",
        cache_hit ? "" : cache_file.string().c_str());
  }
  std::printf("# rating: ISO 6336-2/-3:2006 method B, ISO 1328 class %d; S-N beyond knee: %s\n",
              args.accuracy_grade,
              options.branch == mf::KneeBranch::kHaibach ? "Haibach, slope -1/(2m-1)"
                                                         : "ISO life-factor line (0.85 at 1e10)");
  const mf::LoadSample rated_loads =
      channels.quasi_static_loads(drivetrain.turbine.rated_torque_nm);
  if (args.k_h_beta > 0.0) {
    std::printf("# K_Hβ = %.3f (--k-h-beta override, all meshes and loads)\n", args.k_h_beta);
  } else {
    std::printf(
        "# K_Hβ: ISO 6336-1 method C per load (lead modification %s, f_ma = %.2f·f_Hβ, pinion s/l "
        "= %.2f, contact pattern %s: F_βx by eq. %s); at rated torque:",
        args.lead.c_str(), args.f_ma_factor, args.pinion_offset, args.contact_pattern.c_str(),
        options.rating.face_load.contact_pattern_verified ? "(53) Cor.1" : "(52)");
    for (std::size_t m = 0; m < channels.mesh_count(); ++m) {
      std::printf(" %s %.3f", channels.mesh_id(m).c_str(),
                  channels.mesh(m).face_load(rated_loads.mesh_force_n[m]).k_h_beta);
    }
    std::printf("\n");
  }
  const auto bearing_rows = app::fatigue::bearing_rating_rows(drivetrain, channels);
  std::printf("%s", app::fatigue::bearing_rating_text(channels, bearing_rows).c_str());
  std::printf(
      "# rows %zu: used %zu, rejected %zu (non-numeric %zu, time %zu, speed %zu, wind %zu, other "
      "range %zu, beyond the load spectrum %zu), no data %zu; gaps %zu (%.1f h missing)\n",
      h.rows, h.rows_used, h.rows_rejected, h.rejected_nonnumeric, h.rejected_time,
      h.rejected_speed, h.rejected_wind, h.rejected_range, h.rejected_spectrum, h.rows_no_data,
      h.gaps, h.gap_s / 3600.0);
  if (h.rejected_spectrum > 0) {
    const double rated = drivetrain.turbine.rated_torque_nm;
    std::printf(
        "# %zu rows beyond the load spectrum (torque above %.1f x rated, up to %.2f x rated, or "
        "speed above %.3g rpm) were not accumulated: their damage is NOT in the totals below (a "
        "torque column in kN·m or the wrong --torque-from?)\n",
        h.rejected_spectrum, spectrum.grid.torque_max_nm / rated, h.max_rejected_torque_nm / rated,
        spectrum.grid.speed_max_rpm);
  }
  std::printf(
      "# period %.0f s; covered %.3f days (%.3f years); torque from: torque_nm %zu rows, "
      "P/(eta*omega) %zu, "
      "wind model %zu\n",
      h.period_s, days, h.covered_s / kYearS, h.torque_rows_measured, h.torque_rows_power,
      h.torque_rows_wind);
  std::printf("%-9s %-16s %-8s %12s %12s %10s %10s %10s %10s\n", "component", "detail", "mode",
              "damage", "per_day", "rul_y", "rul_short_y", "rul_low_y", "rul_high_y");
  std::vector<std::string> exceeded;
  for (std::size_t c = 0; c < channels.channel_count(); ++c) {
    const mf::Channel& ch = channels.channel(c);
    const mf::RulEstimate& e = h.rul[c];
    if (h.damage[c] >= 1.0) {
      // Past its life: no remaining life to print, the date it was used up instead.
      std::printf("%-9s %-16s %-8s %12.4e %12.4e %10s %10s %10s %10s\n", ch.component.c_str(),
                  ch.detail.empty() ? "-" : ch.detail.c_str(), mf::failure_mode_name(ch.mode),
                  h.damage[c], days > 0 ? h.damage[c] / days : 0.0, "exceeded", "exceeded",
                  "exceeded", "exceeded");
      exceeded.push_back(ch.component + (ch.detail.empty() ? "" : " " + ch.detail) + " " +
                         mf::failure_mode_name(ch.mode) + ": D = " + std::to_string(h.damage[c]) +
                         ", life exceeded since " + time_text(h.exceeded_at_s[c]));
      continue;
    }
    std::printf("%-9s %-16s %-8s %12.4e %12.4e %10.3g %10.3g %10.3g %10.3g\n", ch.component.c_str(),
                ch.detail.empty() ? "-" : ch.detail.c_str(), mf::failure_mode_name(ch.mode),
                h.damage[c], days > 0 ? h.damage[c] / days : 0.0, e.rul_s / kYearS,
                e.rul_short_term_s / kYearS, e.rul_low_s / kYearS, e.rul_high_s / kYearS);
  }
  for (const auto& line : exceeded) std::printf("# PAST ITS LIFE: %s\n", line.c_str());
  const mf::Channel& bc = channels.channel(h.breakdown_channel);
  std::printf(
      "# %s %s damage by rotor torque (bins of 0.1 x rated): share of time, share of damage, "
      "damage per hour\n",
      bc.component.c_str(), mf::failure_mode_name(bc.mode));
  const double dtot = h.damage[h.breakdown_channel];
  for (std::size_t b = 0; b < app::fatigue::kTorqueBins; ++b) {
    if (h.bin_time_s[b] <= 0.0) continue;
    std::printf("#   %.1f-%s x rated: time %6.2f %%, damage %6.2f %%, %.3e /h\n",
                0.1 * static_cast<double>(b),
                b + 1 == app::fatigue::kTorqueBins
                    ? "   "
                    : std::to_string(0.1 * static_cast<double>(b + 1)).substr(0, 3).c_str(),
                100.0 * h.bin_time_s[b] / h.covered_s,
                dtot > 0 ? 100.0 * h.bin_damage[b] / dtot : 0.0,
                h.bin_damage[b] / (h.bin_time_s[b] / 3600.0));
  }
  std::printf(
      "# time: spectrum %.3f s (%s); rows: wall %.3f s, cpu %.3f s = %.0f rows per cpu second\n",
      spectrum_s, cache_hit ? "from cache" : "built", rows_s, rows_cpu_s,
      static_cast<double>(h.rows) / std::max(rows_cpu_s, 1e-9));
  if (args.bench) {
    std::printf(
        "# bench: reading only (baseline, same file, same run): wall %.3f s, cpu %.3f s; "
        "damage pass / reading only (cpu) = %.2f\n",
        read_only_s, read_only_cpu_s, rows_cpu_s / std::max(read_only_cpu_s, 1e-9));
  }

  app::fatigue::DayDistribution dist;
  const std::size_t dc = h.breakdown_channel;
  if (hopt.per_day) {
    dist = app::fatigue::day_distribution(h.days, dc, 86400.0 - 0.5 * h.period_s, kPaperWindMps,
                                          kNearestDays, kPaperWindBandMps);
    const std::string name =
        channels.channel(dc).component + " " + mf::failure_mode_name(channels.channel(dc).mode);
    std::printf("# per day: %s damage over %zu full UTC days (%zu partial days left out)\n",
                name.c_str(), dist.full_days, dist.partial_days);
    std::printf(
        "#   min %.3e  Q1 %.3e  median %.3e  Q3 %.3e  max %.3e  mean %.3e  (paper, its one day: "
        "%.3e)\n",
        dist.all.min, dist.all.q1, dist.all.median, dist.all.q3, dist.all.max, dist.all.mean,
        kPaperDayDamage);
    const app::fatigue::Quantiles& b = dist.band;
    if (b.count > 0) {
      std::printf(
          "#   %zu full days at the paper's check point (daily mean wind %.2f ± %.2f m/s): median "
          "%.3e  Q1 %.3e  Q3 %.3e  min %.3e  max %.3e  mean %.3e  (paper: %.3e)\n",
          b.count, kPaperWindMps, kPaperWindBandMps, b.median, b.q1, b.q3, b.min, b.max, b.mean,
          kPaperDayDamage);
    } else {
      std::printf("#   no full day at the paper's check point (daily mean wind %.2f ± %.2f m/s)\n",
                  kPaperWindMps, kPaperWindBandMps);
    }
    std::printf("#   full days nearest the paper's operating point (daily mean wind %.2f m/s):\n",
                kPaperWindMps);
    for (std::size_t i : dist.nearest) {
      std::printf("#     %s  mean wind %5.2f m/s  damage %.3e\n", utc_date(h.days[i].day).c_str(),
                  h.days[i].mean_wind_mps(), h.days[i].damage[dc]);
    }
    if (!args.per_day_csv.empty()) {
      std::ofstream out(args.per_day_csv);
      out << "date,covered_s,mean_wind_mps";
      for (std::size_t c = 0; c < channels.channel_count(); ++c) {
        const mf::Channel& ch = channels.channel(c);
        out << ',' << ch.component << (ch.detail.empty() ? "" : " " + ch.detail) << ' '
            << mf::failure_mode_name(ch.mode);
      }
      out << '\n';
      char buf[32];
      for (const auto& day : h.days) {
        out << utc_date(day.day) << ',' << day.covered_s << ',' << day.mean_wind_mps();
        for (double v : day.damage) {
          std::snprintf(buf, sizeof buf, ",%.6e", v);
          out << buf;
        }
        out << '\n';
      }
      if (!out) throw CommandError("--per-day-csv: cannot write '" + args.per_day_csv + "'");
    }
  }

  if (!args.json.empty()) {
    nlohmann::json j;
    j["format"] = "drivetwin-damage/1";
    j["file"] = args.file;
    j["drivetrain"] = drivetrain.name;
    j["spectrum"] = {{"source", rows_mode ? "dynamics-rows" : src},
                     {"k_a", args.k_a},
                     {"cache", rows_mode ? "none" : (cache_hit ? "hit" : "built")},
                     {"rom_rate_hz", args.rom_rate_hz},
                     {"rom_cutoff_hz", args.rom_cutoff_hz}};
    j["rating"] = {{"k_h_beta", args.k_h_beta > 0.0 ? nlohmann::json(args.k_h_beta)
                                                    : nlohmann::json("iso6336-1-method-c")},
                   {"lead_modification", args.lead},
                   {"contact_pattern", args.contact_pattern},
                   {"f_ma_factor", args.f_ma_factor},
                   {"pinion_offset_ratio", args.pinion_offset},
                   {"accuracy_grade", args.accuracy_grade},
                   {"sn_beyond_knee", args.sn}};
    for (std::size_t m = 0; m < channels.mesh_count(); ++m) {
      const mf::FaceLoad f = channels.mesh(m).face_load(rated_loads.mesh_force_n[m]);
      j["rating"]["k_h_beta_at_rated"][channels.mesh_id(m)] = f.k_h_beta;
    }
    for (std::size_t b = 0; b < channels.bearing_count(); ++b) {
      j["rating"]["bearing_c_n"][channels.bearing_id(b)] = channels.bearing(b).dynamic_rating_n;
    }
    j["rating"]["bearing_life"] = app::fatigue::bearing_rating_json(channels, bearing_rows);
    j["rows"] = {{"total", h.rows},
                 {"used", h.rows_used},
                 {"rejected", h.rows_rejected},
                 {"no_data", h.rows_no_data},
                 {"gaps", h.gaps},
                 {"gap_s", h.gap_s},
                 {"rejected_nonnumeric", h.rejected_nonnumeric},
                 {"rejected_time", h.rejected_time},
                 {"rejected_speed", h.rejected_speed},
                 {"rejected_wind", h.rejected_wind},
                 {"rejected_range", h.rejected_range},
                 {"rejected_beyond_spectrum", h.rejected_spectrum}};
    j["period_s"] = h.period_s;
    j["covered_s"] = h.covered_s;
    j["first_t_s"] = h.first_t_s;
    j["last_t_s"] = h.last_t_s;
    for (std::size_t c = 0; c < channels.channel_count(); ++c) {
      const mf::Channel& ch = channels.channel(c);
      const mf::RulEstimate& e = h.rul[c];
      j["channels"].push_back({{"component", ch.component},
                               {"detail", ch.detail},
                               {"mode", mf::failure_mode_name(ch.mode)},
                               {"damage", h.damage[c]},
                               {"damage_per_day", days > 0 ? h.damage[c] / days : 0.0},
                               {"rul_years", num(e.rul_s / kYearS)},
                               {"exceeded_since_t_s", num(h.exceeded_at_s[c])},
                               {"rul_short_term_years", num(e.rul_short_term_s / kYearS)},
                               {"rul_low_years", num(e.rul_low_s / kYearS)},
                               {"rul_high_years", num(e.rul_high_s / kYearS)}});
    }
    for (const auto& i : h.issues)
      j["issues"].push_back({{"row", i.row}, {"field", i.field}, {"message", i.message}});
    if (hopt.per_day) {
      j["per_day"] = quantiles_json(dist.all);
      j["per_day"]["channel"] = dc;
      j["per_day"]["full_days"] = dist.full_days;
      j["per_day"]["partial_days"] = dist.partial_days;
      j["per_day"]["paper_wind_band"] = quantiles_json(dist.band);
      j["per_day"]["paper_wind_band"]["wind_mps"] = kPaperWindMps;
      j["per_day"]["paper_wind_band"]["band_mps"] = kPaperWindBandMps;
      j["per_day"]["paper_wind_band"]["days"] = dist.band.count;
      for (std::size_t i : dist.nearest) {
        j["per_day"]["nearest_paper_wind"].push_back({{"date", utc_date(h.days[i].day)},
                                                      {"mean_wind_mps", h.days[i].mean_wind_mps()},
                                                      {"damage", h.days[i].damage[dc]}});
      }
    }
    j["timing_s"] = {{"spectrum", spectrum_s}, {"rows_wall", rows_s}, {"rows_cpu", rows_cpu_s}};
    j["torque_rows"] = {{"torque_nm", h.torque_rows_measured},
                        {"power", h.torque_rows_power},
                        {"wind_model", h.torque_rows_wind}};
    const std::string text = j.dump(2) + "\n";
    if (args.json == "-") {
      std::fputs(text.c_str(), stdout);
    } else {
      std::ofstream out(args.json);
      out << text;
      if (!out) throw CommandError("--json: cannot write '" + args.json + "'");
    }
  }
  // Rejected rows are bad input: the result above covers the good rows, the exit says so.
  if (h.rows_rejected > 0) app::cli::exit_status() = 2;
}

void setup_damage(CLI::App& sub) {
  auto args = std::make_shared<DamageArgs>();
  sub.add_option(
         "scada", args->file,
         "SCADA CSV (bundle columns, or --columns), or builtin:NAME for an embedded data file")
      ->required();
  app::config::add_drivetrain_option(sub, args->drivetrain);
  sub.add_option(
         "--columns", args->columns,
         "Column mapping: auto (bundle, else kelmarsh), bundle, kelmarsh, or field=Column;...")
      ->capture_default_str();
  sub.add_option("--torque-from", args->torque_from,
                 "Rotor torque source: auto (torque_nm, else P/(eta*omega), else wind model), "
                 "torque, power, "
                 "wind, wind-steady (wind model with its own steady-state speed)")
      ->capture_default_str()
      ->check(app::cli::one_of({"auto", "torque", "power", "wind", "wind-steady"}));
  sub.add_flag("--bench", args->bench,
               "Also time a reading-only pass (baseline) and print the ratio");
  sub.add_option("--json", args->json, "Write a JSON summary to this file ('-' = stdout)");
  sub.add_option("--spectrum", args->spectrum,
                 "Load spectrum source: quasi-static (the fallback: mean mesh forces) | dynamics "
                 "(ROM per grid point, interpolated) | dynamics-rows (ROM at every row's own "
                 "operating point: no interpolation, one simulation per distinct row; short "
                 "histories)")
      ->capture_default_str()
      ->check(app::cli::one_of({"quasi-static", "dynamics", "dynamics-rows"}));
  sub.add_option("--rom-rate", args->rom_rate_hz,
                 "Dynamics spectrum: the ROM's sample (step) rate [Hz]; `drivetwin run` steps its "
                 "ROM at period / rom_steps_per_cycle")
      ->capture_default_str()
      ->check(app::cli::number_in(256.0, 1e6, "Hz"));
  sub.add_option("--rom-cutoff", args->rom_cutoff_hz,
                 "Dynamics spectrum: the ROM's mode cut-off [Hz]")
      ->capture_default_str()
      ->check(app::cli::number_in(10.0, 2500.0, "Hz"));
  sub.add_option("--cache-dir", args->cache_dir,
                 "Spectrum cache folder (default $XDG_CACHE_HOME/drivetwin)");
  sub.add_flag("--no-cache", args->no_cache, "Always rebuild the spectrum, write no cache");
  sub.add_option("--period", args->period_s, "SCADA period [s] (default: detected)")
      ->check(app::cli::number_in(0.0, 366.0 * 86400.0, "s", true));
  sub.add_option("--sn", args->sn, "S-N beyond the knee: haibach | iso")
      ->capture_default_str()
      ->check(app::cli::one_of({"haibach", "iso"}));
  sub.add_option("--k-a", args->k_a, "Application factor K_A of the quasi-static spectrum")
      ->capture_default_str()
      ->check(app::cli::number_in(1.0, 10.0));
  sub.add_option(
         "--k-h-beta", args->k_h_beta,
         "Face load factor K_Hbeta as a constant override (default: ISO 6336-1 method C per load)")
      ->check(app::cli::number_in_or(0.0, "ISO 6336-1 method C", 1.0, 10.0));
  sub.add_option("--lead", args->lead,
                 "Lead modification for K_Hbeta method C: none, helix, helix-crowning, crowning, "
                 "end-relief")
      ->capture_default_str();
  sub.add_option(
         "--contact-pattern", args->contact_pattern,
         "K_Hbeta method C: unverified (ISO 6336-1 eq. 52) | verified (a favourable contact "
         "pattern under load has been checked: eq. 53 of Cor.1:2008)")
      ->capture_default_str();
  sub.add_option("--f-ma", args->f_ma_factor,
                 "Mesh misalignment f_ma as a fraction of f_Hbeta (1: no adjustment)")
      ->capture_default_str()
      ->check(app::cli::number_in(0.0, 1.0));
  sub.add_option("--pinion-offset", args->pinion_offset,
                 "Parallel-stage pinion offset s/l from mid-span (K_Hbeta method C)")
      ->capture_default_str()
      ->check(app::cli::number_in(0.0, 0.5, "", false, true));
  sub.add_option("--grade", args->accuracy_grade, "ISO 1328-1 accuracy class (K_Halpha)")
      ->capture_default_str()
      ->check(app::cli::integer_in(app::config::kMinAccuracyGrade, app::config::kMaxAccuracyGrade,
                                   "ISO 1328-1:2013 classes"));
  sub.add_option("--oil-viscosity-40", args->lubrication.viscosity_40c_mm2_s,
                 "Bearing oil's kinematic viscosity at 40 degC [mm2/s] (ISO 281 a_ISO)")
      ->capture_default_str()
      ->check(app::cli::number_in(1.0, 10000.0, "mm2/s", false, true));
  sub.add_option("--oil-viscosity-100", args->lubrication.viscosity_100c_mm2_s,
                 "... and at 100 degC [mm2/s]")
      ->capture_default_str()
      ->check(app::cli::number_in(1.0, 10000.0, "mm2/s", false, true));
  sub.add_option("--oil-temperature", args->lubrication.temperature_c,
                 "Bearing operating temperature [degC] (ISO 281 a_ISO)")
      ->capture_default_str()
      ->check(app::cli::number_in(-40.0, 150.0, "degC"));
  sub.add_option("--contamination", args->lubrication.contamination_factor,
                 "ISO 281 contamination factor e_C (Table 13: normal cleanliness 0.6-0.8 for "
                 "D_pw >= 100 mm)")
      ->capture_default_str()
      ->check(app::cli::number_in(0.0, 1.0));
  sub.add_flag("--basic-life", args->basic_life,
               "Bearings at their ISO 281 basic rating life L10 (no a_ISO)");
  sub.add_flag("--no-progress", args->no_progress, "No progress bar on a terminal");
  sub.add_flag("--per-day", args->per_day,
               "Distribution of the most damaged gear-contact channel's damage per full UTC day, "
               "and the days "
               "nearest the paper's operating point");
  sub.add_option("--per-day-csv", args->per_day_csv,
                 "Write every day's damage per channel to this CSV (implies --per-day)");
  sub.callback([args] { run(*args); });
}

const bool kDamageRegistered = app::cli::register_command(
    {"damage", "Fatigue damage and remaining life per gear and bearing from SCADA history",
     &setup_damage});

}  // namespace
