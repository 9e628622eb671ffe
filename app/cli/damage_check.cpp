// `drivetwin damage-check <scada.csv>`: online accumulator versus history mode over the
// same stretch of SCADA (default: the first 6 ten-minute rows, one hour).
//
// Online: the dynamics model's ROM stepped continuously at the sample rate, as the
// real-time loop runs it, with each row's rotor speed and torque held over the row's
// period; every sample's mesh forces and bearing reactions go through the
// DamageAccumulator. History: the same rows through `damage`'s path — the load spectrum
// built from the same ROM at the same sample rate on the (torque, speed) grid, then
// interpolated per row. The difference per channel measures what history mode loses
// (grid interpolation, short simulation windows, start-up and step transients).
//
// Rows must carry t_s, rotor_speed_rpm and torque_nm (e.g. `drivetwin synth-scada`).
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "cli/command.hpp"
#include "cli/options.hpp"
#include "cli/sample_rate_check.hpp"
#include "config/drivetrain_file.hpp"
#include "fatigue/damage_history.hpp"
#include "fatigue/dynamics_spectrum.hpp"
#include "fatigue/progress.hpp"
#include "hal/scada_csv.hpp"
#include "model/dynamics/rom.hpp"
#include "model/fatigue/damage_accumulator.hpp"
#include "recording/bundle_check.hpp"
#include "wind/scada_rows.hpp"

namespace {

namespace mf = model::fatigue;
using app::cli::CommandError;

struct CheckArgs {
  std::string file;
  std::string drivetrain;
  std::size_t rows = 6;
  double period_s = 600.0;
  double sample_rate_hz = 4096.0;
  double cutoff_hz = 1500.0;
  bool no_progress = false;
};

// The first --rows rows, read before the spectrum is built (minutes) through the policy
// every SCADA reader shares (app/wind/scada_rows.hpp). The comparison needs every one of
// them in both paths, so here a rejected row — or one without t_s, rotor_speed_rpm or
// torque_nm — is an error naming it, not a row skipped.
void check_rows(const CheckArgs& a, const model::Drivetrain& d) {
  hal::ScadaCsvReader scan;
  if (!scan.open(a.file, hal::bundle_scada_columns())) throw CommandError(scan.error());
  const app::wind::ScadaLimits limits(d);
  app::wind::RowRejections rejected;
  std::string missing;
  std::size_t read = 0;
  hal::ScadaRow row;
  while (read < a.rows) {
    const hal::ScadaReadResult res = scan.next(row);
    if (res == hal::ScadaReadResult::kEnd) break;
    ++read;
    if (res == hal::ScadaReadResult::kError) {
      rejected.unreadable(scan, read);
      continue;
    }
    if (!rejected.plausible(limits, scan, row)) continue;
    if (missing.empty() && (!row.has_time() || !row.has(hal::ScadaQuantity::kRotorSpeed) ||
                            !row.has(hal::ScadaQuantity::kRotorTorque))) {
      missing = a.file + ": row " + std::to_string(row.row) + " (line " + std::to_string(row.line) +
                "): needs t_s, rotor_speed_rpm and torque_nm";
    }
  }
  if (read < a.rows) {
    throw CommandError(a.file + ": " + std::to_string(read) + " data rows; --rows asks for " +
                       std::to_string(a.rows));
  }
  if (rejected.rows_rejected > 0) {
    std::string listed;
    for (const app::wind::ScadaIssue& i : rejected.issues) listed += "; " + i.message;
    throw CommandError(a.file + ": the first " + std::to_string(a.rows) +
                       " rows are compared, every one is needed: " + rejected.summary() + listed);
  }
  if (!missing.empty()) throw CommandError(missing);
}

void run(const CheckArgs& a) {
  const model::Drivetrain d = app::config::load_drivetrain(a.drivetrain);
  const std::string rate_error = app::cli::check_sample_rate(
      "--sample-rate", a.sample_rate_hz, d, app::recording::operating_range(d).max_rotor_speed_rpm,
      a.cutoff_hz, "--cutoff");
  if (!rate_error.empty()) throw CommandError(rate_error);
  // The file before the spectrum (minutes): a missing or malformed file is said at once.
  hal::ScadaCsvReader reader;
  if (!reader.open(a.file, hal::bundle_scada_columns())) throw CommandError(reader.error());
  check_rows(a, d);
  const mf::ChannelSet channels(d, mf::ChannelOptions{});
  if (!channels.valid()) throw CommandError("drivetrain '" + d.name + "': " + channels.error());
  app::fatigue::DynamicsSpectrumSettings ds;
  ds.sample_rate_hz = a.sample_rate_hz;
  ds.rom_cutoff_hz = a.cutoff_hz;

  // History: spectrum from the ROM (not cached: the check's sample rate is its own).
  const mf::SpectrumGrid grid = app::fatigue::dynamics_grid(d);
  std::string error, sim_error;
  std::fprintf(stderr, "damage-check: building the dynamics load spectrum (%u points)...\n",
               grid.torque_points * grid.speed_points);
  const bool progress_shown = app::fatigue::show_progress(a.no_progress, STDERR_FILENO);
  mf::LoadSpectrum spectrum;
  {
    app::fatigue::ProgressLine progress(
        progress_shown, "load spectrum (dynamics model)", "points",
        static_cast<double>(grid.torque_points) * static_cast<double>(grid.speed_points));
    const mf::LoadSimulator simulator =
        app::fatigue::dynamics_simulator(d, channels, ds, &sim_error);
    double simulated = 0.0;
    spectrum = mf::build_load_spectrum(
        channels, grid, mf::SpectrumSource::kDynamics,
        [&](double torque_nm, double rotor_rpm, mf::LoadSeries& series) {
          const bool ok = simulator(torque_nm, rotor_rpm, series);
          progress.update(++simulated);
          return ok;
        },
        &error);
  }
  if (spectrum.channel_count == 0) throw CommandError(error + ": " + sim_error);
  app::fatigue::HistoryOptions ho;
  ho.period_s = a.period_s;
  ho.max_rows = a.rows;
  ho.torque_from = app::fatigue::TorqueFrom::kTorque;
  const app::fatigue::HistoryResult h =
      app::fatigue::run_history(reader, d, channels, spectrum, ho);
  if (h.rows_used != a.rows) {
    throw CommandError(a.file + ": only " + std::to_string(h.rows_used) + " of the first " +
                       std::to_string(a.rows) +
                       " rows are usable (need t_s, rotor_speed_rpm, torque_nm)");
  }

  // Online: the ROM stepped continuously.
  model::dynamics::RomSettings rs;
  rs.dt_s = 1.0 / a.sample_rate_hz;
  rs.cutoff_hz = a.cutoff_hz;
  const auto data = model::dynamics::build_rom(d, d.dynamics, rs, &error);
  if (!data) throw CommandError("dynamics model: " + error);
  const app::fatigue::RomLoadConverter conv(d, channels, *data);
  if (!conv.valid()) throw CommandError(conv.error());
  mf::AccumulatorConfig cfg;
  cfg.tick_s = 1.0 / a.sample_rate_hz;
  mf::DamageAccumulator online(channels, cfg);
  auto rom = std::make_unique<model::dynamics::Rom>(*data);
  hal::ScadaCsvReader rows;
  if (!rows.open(a.file, hal::bundle_scada_columns())) throw CommandError(rows.error());
  hal::ScadaRow row;
  mf::LoadSample loads;
  model::dynamics::RomOutputs o;
  const auto steps = static_cast<long long>(std::llround(a.period_s * a.sample_rate_hz));
  app::fatigue::ProgressLine row_progress(progress_shown, "online (ROM stepped per sample)", "rows",
                                          static_cast<double>(a.rows));
  for (std::size_t k = 0; k < a.rows; ++k) {
    if (rows.next(row) != hal::ScadaReadResult::kRow) throw CommandError(rows.error());
    const double rpm = row.get(hal::ScadaQuantity::kRotorSpeed),
                 torque = std::abs(row.get(hal::ScadaQuantity::kRotorTorque));
    const model::dynamics::RomInputs in{rpm, torque};
    if (k == 0) rom->reset(in);
    for (long long i = 0; i < steps; ++i) {
      rom->step(in, o);
      conv.convert(o.mesh_force_n.data(), o.bearing_force_x_n.data(), o.bearing_force_y_n.data(),
                   torque, loads);
      online.step(loads, rpm, 1);
    }
    row_progress.update(static_cast<double>(k + 1));
  }
  row_progress.finish();

  std::printf(
      "# damage-check %s: %zu rows of %.0f s, ROM at %.0f Hz (cut-off %.0f Hz), drivetrain %s "
      "(Rayleigh eta = %g 1/s, zeta = %g s)\n",
      a.file.c_str(), a.rows, a.period_s, a.sample_rate_hz, a.cutoff_hz, d.name.c_str(),
      d.dynamics.rayleigh_eta, d.dynamics.rayleigh_zeta);
  std::printf("%-9s %-16s %-8s %12s %12s %9s\n", "component", "detail", "mode", "online", "history",
              "diff_pct");
  double worst = 0.0;
  for (std::size_t c = 0; c < channels.channel_count(); ++c) {
    const mf::Channel& ch = channels.channel(c);
    const double on = online.damage(c), hi = h.damage[c];
    const double pct = on > 0 ? 100.0 * (hi - on) / on : 0.0;
    if (on > 1e-12) worst = std::max(worst, std::abs(pct));
    std::printf("%-9s %-16s %-8s %12.4e %12.4e %9.2f\n", ch.component.c_str(),
                ch.detail.empty() ? "-" : ch.detail.c_str(), mf::failure_mode_name(ch.mode), on, hi,
                pct);
  }
  std::printf(
      "# largest |history − online| / online over channels with online damage > 1e-12: %.2f %%\n",
      worst);
}

void setup_damage_check(CLI::App& sub) {
  auto args = std::make_shared<CheckArgs>();
  sub.add_option("scada", args->file,
                 "SCADA CSV with t_s, rotor_speed_rpm, torque_nm (bundle columns)")
      ->required();
  app::config::add_drivetrain_option(sub, args->drivetrain);
  // The same ranges as `damage`'s (--period, --rom-rate, --rom-cutoff); the rate against
  // the turbine's mesh lines and the cut-off is checked once the drivetrain is loaded.
  sub.add_option("--rows", args->rows, "Rows to compare")
      ->capture_default_str()
      ->check(app::cli::integer_in(1, 100000, "rows"));
  sub.add_option("--period", args->period_s, "Row period [s]")
      ->capture_default_str()
      ->check(app::cli::number_in(0.0, 86400.0, "s", true));
  sub.add_option("--sample-rate", args->sample_rate_hz, "ROM sample rate [Hz]")
      ->capture_default_str()
      ->check(app::cli::number_in(256.0, 1e6, "Hz"));
  sub.add_option("--cutoff", args->cutoff_hz, "ROM mode cut-off [Hz]")
      ->capture_default_str()
      ->check(app::cli::number_in(10.0, 2500.0, "Hz"));
  sub.add_flag("--no-progress", args->no_progress, "No progress line on a terminal");
  sub.callback([args] { run(*args); });
}

const bool kDamageCheckRegistered = app::cli::register_command(
    {"damage-check",
     "Online accumulator (ROM stepped per sample) vs history mode over the same SCADA rows",
     &setup_damage_check});

}  // namespace
