// `drivetwin synth-scada --years N --out FILE`: a deterministic synthetic SCADA history
// (10-minute rows by default) with given site wind statistics, for history-mode runs
// over years (`drivetwin damage`).
//
// Wind: 10-minute mean wind speeds with a Weibull(k, c) marginal and two-scale persistence
// (app/wind/synthetic_wind.hpp: a Gaussian copula over the sum of a slow and a fast AR(1)).
// An annual and a diurnal cycle multiply the Weibull scale (first harmonics, by the row's UTC
// day of the year and hour of the day). Defaults are fitted to the Kelmarsh turbine 1
// 10-minute data, days 1–6 of every month of 2019 (shared/data/kelmarsh/kelmarsh-t1-2019.csv,
// Plumley 2022, CC-BY-4.0) by tools/wind_floor/fit_synthetic_wind.py: the cycles (±10.3 %
// peaking late January, ±2.2 % peaking at 17 h UTC), then k = 2.666, c = 6.733 m/s by the
// method of moments on the wind with the cycles divided out, the persistence by the
// correlation at lags from 10 minutes to 3 days. Pass --weibull-k/--weibull-c and the cycle
// options for other statistics, --lag1 for the former single AR(1).
// Operating point: the turbine controller's steady state of the wind load model
// (model/wind): rotor speed and rotor torque; power = T·ω·η. Rows carry 10-minute means
// only: no turbulence within the 10 minutes, no stops other than below cut-in / above cut-out.
// Random numbers: std::mt19937_64 (fully specified by the standard) with our own
// Box–Muller transform, so the file is identical on every platform for a given seed.
//
// Turbulent mode (`--turbulence A|B|C|none`): rows every `--resolution` seconds (default 1)
// from a rotor model driven by turbulent wind inside each 10-minute row. The 10-minute mean
// winds come from an existing SCADA file (`--from-10min FILE`, e.g.
// builtin:kelmarsh-day.csv; each row's time and mean wind), from a constant
// (`--mean-wind V`), or from the two-scale Weibull generator above. Inside each row: IEC
// 61400-1 normal turbulence with the Kaimal spectrum (model/wind/turbulence.hpp), averaged
// over the rotor disc with IEC's exponential coherence (--point-wind: the hub point's wind,
// an upper bound of the fluctuations), fed to the
// one-degree-of-freedom rotor with its speed and pitch control (model/wind/rotor_model.hpp).
// Each output row is the mean over its interval of the wind, rotor speed, electrical
// power, pitch, and the low-speed shaft (gearbox input) torque T_aero − J_rotor·dω/dt.
// `none` runs the same rotor model on the constant row means (the control case). A row
// whose mean wind is below cut-in or at/above cut-out is parked (speed, torque, power 0);
// an operating row after a parked one starts at the rotor's steady state for its mean.
// `--out-10min FILE` also writes the 10-minute means of the same run (same columns).
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cli/command.hpp"
#include "cli/options.hpp"
#include "config/drivetrain_file.hpp"
#include "data/embedded.hpp"
#include "fatigue/progress.hpp"
#include "hal/scada_csv.hpp"
#include "model/drivetrain/kinematics.hpp"
#include "model/dynamics/full_model.hpp"
#include "model/wind/rotor_model.hpp"
#include "model/wind/turbulence.hpp"
#include "model/wind/wind_load.hpp"
#include "wind/synthetic_wind.hpp"

namespace {

using app::cli::CommandError;
constexpr double kPi = 3.14159265358979323846;

struct SynthArgs {
  std::string out;
  std::string drivetrain;
  double years = 11.0;
  double period_s = 600.0;
  double weibull_k = app::wind::SyntheticWindParameters{}.weibull_k;
  double weibull_c = app::wind::SyntheticWindParameters{}.weibull_c;
  double lag1 = -1.0;  // ≥ 0: a single AR(1) with this lag-1 correlation per 10 minutes
  app::wind::SyntheticWindParameters persistence;  // the two-scale defaults
  unsigned long long seed = 1;
  double start_s = 1420070400.0;  // 2015-01-01T00:00:00Z
  double days = 0.0;              // > 0: length in days instead of --years
  // Turbulent mode
  std::string turbulence;  // "", A, B, C, none
  double resolution_s = 1.0;
  std::string from_10min;
  double mean_wind = 0.0;  // [m/s] constant 10-minute mean wind, when mean_wind_given
  bool mean_wind_given = false;
  std::string turbulent_only_given;  // a turbulent-mode option given without --turbulence
  double hub_height_m = 80.0;
  double rotor_inertia = model::wind::RotorModelParameters{}.rotor_inertia_kg_m2;
  double step_s = 0.025;
  double wind_sample_s = 0.25;
  std::string out_10min;
  bool point_wind = false;
  bool no_progress = false;
};

constexpr double kSynthSegmentS = 600.0;  // [s] one SCADA row: the turbulence segment

// The 10-minute mean wind generator of the arguments, for rows `period_s` apart.
app::wind::SyntheticWind make_synthetic_wind(const SynthArgs& a, double period_s) {
  app::wind::SyntheticWindParameters p = a.persistence;
  p.weibull_k = a.weibull_k;
  p.weibull_c = a.weibull_c;
  if (a.lag1 >= 0.0) {
    if (!(a.lag1 > 0.0 && a.lag1 < 1.0)) throw CommandError("--lag1 must be in (0, 1)");
    p.slow_weight = 1.0;
    p.slow_time_constant_s = -600.0 / std::log(a.lag1);
  }
  const char* what = nullptr;
  if (!app::wind::valid_synthetic_wind(p, period_s, &what)) {
    throw CommandError(std::string("--weibull-k/--weibull-c/--slow-weight/--slow-time-constant/"
                                   "--fast-lag1/--seasonal-*/--diurnal-*/--period: ") +
                       what);
  }
  return {p, period_s, a.seed};
}

void run_synth_steady(const SynthArgs& a) {
  if (!(a.years > 0.0) || !(a.period_s > 0.0))
    throw CommandError("--years and --period must be > 0");
  if (!(a.weibull_k > 0.0) || !(a.weibull_c > 0.0))
    throw CommandError("--weibull-k and --weibull-c must be > 0");
  app::wind::SyntheticWind wind_means = make_synthetic_wind(a, a.period_s);
  const model::Drivetrain d = app::config::load_drivetrain(a.drivetrain);
  const model::wind::WindLoad wind(d.turbine);
  std::FILE* f = std::fopen(a.out.c_str(), "w");
  if (!f) throw CommandError("--out: cannot write '" + a.out + "'");
  std::fprintf(f, "t_s,wind_speed_mps,rotor_speed_rpm,power_kw,torque_nm\n");
  const double length_s = a.days > 0.0 ? a.days * 86400.0 : a.years * 365.25 * 86400.0;
  const auto rows = static_cast<long long>(std::llround(length_s / a.period_s));
  const double eta = d.turbine.drivetrain_efficiency;
  for (long long i = 0; i < rows; ++i) {
    const double t_s = a.start_s + static_cast<double>(i) * a.period_s;
    const double v = wind_means.next(t_s);
    const model::wind::WindLoadOutput o = wind.steady_state(v);
    const double rpm = o.rotor_speed_rad_s * 60.0 / (2.0 * kPi);
    const double p_kw = o.torque_nm * o.rotor_speed_rad_s * eta / 1e3;
    std::fprintf(f, "%.0f,%.3f,%.4f,%.3f,%.1f\n", t_s, v, rpm, p_kw, o.torque_nm);
  }
  if (std::fclose(f) != 0) throw CommandError("--out: write error on '" + a.out + "'");
  std::printf("wrote %lld rows (%.4g days of %.0f s) to %s\n", rows, length_s / 86400.0, a.period_s,
              a.out.c_str());
}

// One 10-minute row of the turbulent mode's input: start time and mean wind.
struct SynthMeanRow {
  double t_s = 0.0;
  double wind_mps = 0.0;
};

std::string synth_number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

// The 10-minute rows of --from-10min: bundle columns, else the Kelmarsh export's;
// "builtin:NAME" reads an embedded data file. Every bad row stops with file, row, column.
std::vector<SynthMeanRow> read_synth_means(const std::string& file) {
  std::string text_name;
  std::optional<std::string_view> text;
  const std::string prefix = "builtin:";
  if (file.rfind(prefix, 0) == 0) {
    text_name = file.substr(prefix.size());
    text = app::data::embedded_file(text_name);
    if (!text) throw CommandError("--from-10min: no embedded data file '" + text_name + "'");
  }
  hal::ScadaCsvReader reader;
  auto open = [&](const hal::ScadaColumns& columns) {
    return text ? reader.open_text(*text, file, columns) : reader.open(file, columns);
  };
  if (!open(hal::bundle_scada_columns())) {
    // A copy (the next open() replaces the reader's error), with what it was tried as.
    const std::string bundle_error = "as bundle columns: " + reader.error();
    if (!open(hal::kelmarsh_scada_columns())) {
      throw CommandError("--from-10min: " + bundle_error +
                         "; as Kelmarsh columns: " + reader.error());
    }
  }
  const char* time_column = reader.time_column_name().c_str();
  const char* wind_column = reader.column_name(hal::ScadaQuantity::kWindSpeed).c_str();
  std::vector<SynthMeanRow> rows;
  hal::ScadaRow row;
  for (;;) {
    const hal::ScadaReadResult r = reader.next(row);
    if (r == hal::ScadaReadResult::kEnd) break;
    if (r == hal::ScadaReadResult::kError) throw CommandError("--from-10min: " + reader.error());
    auto where = [&](const char* column) {
      return file + ": row " + std::to_string(row.row) + " (line " + std::to_string(row.line) +
             "), column '" + column + "': ";
    };
    if (!row.has_time()) throw CommandError(where(time_column) + "empty time");
    if (!row.has(hal::ScadaQuantity::kWindSpeed))
      throw CommandError(where(wind_column) + "empty wind speed (a turbulent row needs its mean)");
    const double t = row.time_s();
    const double v = row.get(hal::ScadaQuantity::kWindSpeed);
    if (v < 0.0 || v > 70.0) {
      throw CommandError(where(wind_column) + "wind speed " + synth_number(v) +
                         " m/s outside 0..70");
    }
    if (!rows.empty() && t < rows.back().t_s + kSynthSegmentS - 1e-6) {
      throw CommandError(where(time_column) + "time " + synth_number(t) +
                         " is less than 600 s after the previous row's (10-minute rows expected)");
    }
    rows.push_back({t, v});
  }
  if (rows.empty()) throw CommandError("--from-10min: " + file + ": no data rows");
  return rows;
}

// Writes one row; the columns of run_synth_steady plus pitch_deg.
void write_synth_row(std::FILE* f, double t_s, double wind, double rpm, double p_kw, double torque,
                     double pitch_deg) {
  std::fprintf(f, "%.0f,%.3f,%.4f,%.3f,%.1f,%.3f\n", t_s, wind, rpm, p_kw, torque, pitch_deg);
}

void run_synth_turbulent(const SynthArgs& a) {
  namespace mw = model::wind;
  mw::TurbulenceSettings ts;
  bool turbulent = true;
  if (a.turbulence == "A") {
    ts.turbulence_class = mw::TurbulenceClass::kA;
  } else if (a.turbulence == "B") {
    ts.turbulence_class = mw::TurbulenceClass::kB;
  } else if (a.turbulence == "C") {
    ts.turbulence_class = mw::TurbulenceClass::kC;
  } else if (a.turbulence == "none") {
    turbulent = false;
  } else {
    throw CommandError("--turbulence: '" + a.turbulence + "' is not one of A, B, C, none");
  }
  ts.hub_height_m = a.hub_height_m;
  ts.segment_s = kSynthSegmentS;
  ts.sample_period_s = a.wind_sample_s;
  const char* what = nullptr;
  if (!mw::valid_turbulence_settings(ts, &what))
    throw CommandError(std::string("--hub-height/--wind-sample: ") + what);
  if (!(a.step_s > 0.0) || !(a.step_s <= a.wind_sample_s))
    throw CommandError("--step must be > 0 and <= --wind-sample");
  if (!(a.resolution_s >= a.step_s) || !(a.resolution_s <= kSynthSegmentS))
    throw CommandError("--resolution must be in [--step, 600] s");
  const double steps_per_out = a.resolution_s / a.step_s;
  const double outs_per_segment = kSynthSegmentS / a.resolution_s;
  const double samples_per_step = a.wind_sample_s / a.step_s;
  auto whole = [](double x) { return std::abs(x - std::round(x)) < 1e-9 * std::max(1.0, x); };
  if (!whole(steps_per_out) || !whole(outs_per_segment) || !whole(samples_per_step)) {
    throw CommandError(
        "--resolution must divide 600 s and be a whole number of --step, and --wind-sample a "
        "whole number of --step");
  }
  if (!a.from_10min.empty() && (a.mean_wind_given || a.days > 0.0)) {
    throw CommandError("--from-10min excludes --mean-wind and --days (the file sets both)");
  }
  if (a.mean_wind_given && !(a.mean_wind >= 0.0 && a.mean_wind < 70.0)) {
    throw CommandError("--mean-wind must be in [0, 70) m/s, not " + synth_number(a.mean_wind));
  }

  const model::Drivetrain d = app::config::load_drivetrain(a.drivetrain);
  // Rotor-effective wind over the description's rotor disc unless --point-wind.
  ts.rotor_radius_m = a.point_wind ? 0.0 : d.turbine.rotor_radius_m;
  if (!mw::valid_turbulence_settings(ts, &what)) {
    throw CommandError(std::string("--drivetrain: ") + what);
  }
  mw::RotorModelParameters rp;
  rp.rotor_inertia_kg_m2 = a.rotor_inertia;
  // Generator rotor inertia (the dynamics model's default) referred to the low-speed shaft.
  const double ratio = model::Kinematics(d).overall_ratio();
  rp.drivetrain_inertia_kg_m2 =
      model::dynamics::StructuralParameters{}.generator_inertia_kg_m2 * ratio * ratio;
  if (!mw::valid_rotor_parameters(d.turbine, rp, &what))
    throw CommandError(std::string("--rotor-inertia / drivetrain: ") + what);
  const mw::RotorModel rotor(d.turbine, rp);
  const mw::WindLoad& load = rotor.wind_load();

  // The 10-minute means.
  std::vector<SynthMeanRow> means;
  if (!a.from_10min.empty()) {
    means = read_synth_means(a.from_10min);
  } else {
    // No default length here: 1-s rows are 86 400 a day, and --years' default is 11.
    if (!(a.days > 0.0))
      throw CommandError("--days must be given and > 0 in turbulent mode (or --from-10min FILE)");
    const double length_s = a.days * 86400.0;
    const auto rows = static_cast<long long>(std::llround(length_s / kSynthSegmentS));
    means.reserve(static_cast<std::size_t>(rows));
    app::wind::SyntheticWind wind_means = make_synthetic_wind(a, kSynthSegmentS);
    for (long long i = 0; i < rows; ++i) {
      const double t_s = a.start_s + static_cast<double>(i) * kSynthSegmentS;
      const double v = a.mean_wind_given ? a.mean_wind : wind_means.next(t_s);
      means.push_back({t_s, v});
    }
  }

  std::FILE* f = std::fopen(a.out.c_str(), "w");
  if (!f) throw CommandError("--out: cannot write '" + a.out + "'");
  std::FILE* f10 = nullptr;
  if (!a.out_10min.empty()) {
    f10 = std::fopen(a.out_10min.c_str(), "w");
    if (!f10) {
      std::fclose(f);
      throw CommandError("--out-10min: cannot write '" + a.out_10min + "'");
    }
  }
  const char* header = "t_s,wind_speed_mps,rotor_speed_rpm,power_kw,torque_nm,pitch_deg\n";
  std::fputs(header, f);
  if (f10) std::fputs(header, f10);

  mw::TurbulentWind wind(ts, a.seed);
  const std::size_t n_samples = wind.samples_per_segment();
  const auto n_out = static_cast<std::size_t>(std::llround(outs_per_segment));
  const auto n_per_out = static_cast<std::size_t>(std::llround(steps_per_out));
  const auto n_per_sample = static_cast<std::size_t>(std::llround(samples_per_step));
  constexpr double kRadSToRpm = 60.0 / (2.0 * 3.14159265358979323846);
  constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;
  const double dt = a.step_s;
  mw::RotorState state;
  bool running = false;
  long long out_rows = 0;
  double max_torque = 0.0;
  double max_pitch = 0.0;
  // ~3 s per simulated day on the shared machine: a progress line over the 10-minute means.
  app::fatigue::ProgressLine progress(app::fatigue::show_progress(a.no_progress, STDERR_FILENO),
                                      "rotor model over the 10-minute means", "means",
                                      static_cast<double>(means.size()));
  for (std::size_t i = 0; i < means.size(); ++i) {
    progress.update(static_cast<double>(i));
    const double v_mean = means[i].wind_mps;
    const bool contiguous_next =
        i + 1 < means.size() && means[i + 1].t_s - means[i].t_s < kSynthSegmentS + 1e-6;
    if (i > 0 && means[i].t_s - means[i - 1].t_s > kSynthSegmentS + 1e-6) {
      wind.reset_neighbours();
      running = false;  // after a gap the rotor starts from its steady state again
    }
    if (turbulent) wind.advance(v_mean, contiguous_next ? means[i + 1].wind_mps : 0.0);
    const mw::OperatingRegion region = load.region_of(v_mean);
    const bool operating =
        region != mw::OperatingRegion::kBelowCutIn && region != mw::OperatingRegion::kAboveCutOut;
    if (operating && !running) state = rotor.steady_state(v_mean);
    running = operating;
    double seg_wind = 0.0, seg_rpm = 0.0, seg_kw = 0.0, seg_torque = 0.0, seg_pitch = 0.0;
    std::size_t step = 0;
    for (std::size_t k = 0; k < n_out; ++k) {
      double s_wind = 0.0, s_speed = 0.0, s_power = 0.0, s_torque = 0.0, s_pitch = 0.0;
      for (std::size_t m = 0; m < n_per_out; ++m, ++step) {
        // Wind at the middle of the step, linear between the samples (held after the last).
        double v = v_mean;
        if (turbulent) {
          const double x = (static_cast<double>(step) + 0.5) / static_cast<double>(n_per_sample);
          const auto j = static_cast<std::size_t>(x);
          const double w = x - static_cast<double>(j);
          const double v0 = wind.wind_mps(j);
          const double v1 = j + 1 < n_samples ? wind.wind_mps(j + 1) : v0;
          v = v0 + w * (v1 - v0);
        }
        s_wind += v;
        if (!operating) continue;
        const mw::RotorStepOutput o = rotor.step(state, v, dt);
        s_speed += o.speed_rad_s;
        s_power += o.electrical_power_w;
        s_torque += o.shaft_torque_nm;
        s_pitch += o.pitch_rad;
      }
      const double inv = 1.0 / static_cast<double>(n_per_out);
      const double row_wind = s_wind * inv, row_rpm = s_speed * inv * kRadSToRpm;
      const double row_kw = s_power * inv / 1e3, row_torque = s_torque * inv;
      const double row_pitch = s_pitch * inv * kRadToDeg;
      write_synth_row(f, means[i].t_s + static_cast<double>(k) * a.resolution_s, row_wind, row_rpm,
                      row_kw, row_torque, row_pitch);
      ++out_rows;
      max_torque = std::max(max_torque, row_torque);
      max_pitch = std::max(max_pitch, row_pitch);
      seg_wind += row_wind;
      seg_rpm += row_rpm;
      seg_kw += row_kw;
      seg_torque += row_torque;
      seg_pitch += row_pitch;
    }
    if (f10) {
      const double inv = 1.0 / static_cast<double>(n_out);
      write_synth_row(f10, means[i].t_s, seg_wind * inv, seg_rpm * inv, seg_kw * inv,
                      seg_torque * inv, seg_pitch * inv);
    }
  }
  progress.update(static_cast<double>(means.size()));
  progress.finish();
  const bool write_error = std::fclose(f) != 0;
  const bool write_error10 = f10 != nullptr && std::fclose(f10) != 0;
  if (write_error) throw CommandError("--out: write error on '" + a.out + "'");
  if (write_error10) throw CommandError("--out-10min: write error on '" + a.out_10min + "'");
  std::printf(
      "wrote %lld rows of %.4g s (%zu 10-minute means, turbulence %s, %s wind, rotor model: "
      "J_rotor %.3g + J_drivetrain %.3g kg·m², step %.3g s) to %s\n",
      out_rows, a.resolution_s, means.size(), a.turbulence.c_str(),
      a.point_wind ? "hub point" : "rotor-effective", rp.rotor_inertia_kg_m2,
      rp.drivetrain_inertia_kg_m2, dt, a.out.c_str());
  std::printf("largest row torque %.0f N·m (rated %.0f), largest row pitch %.2f°\n", max_torque,
              d.turbine.rated_torque_nm, max_pitch);
  if (f10) {
    std::printf("wrote %zu 10-minute means of the same run to %s\n", means.size(),
                a.out_10min.c_str());
  }
}

void run(const SynthArgs& a) {
  if (a.turbulence.empty()) {
    if (!a.turbulent_only_given.empty()) {
      throw CommandError(a.turbulent_only_given + " needs --turbulence (turbulent mode)");
    }
    run_synth_steady(a);
  } else {
    run_synth_turbulent(a);
  }
}

void setup_synth_scada(CLI::App& sub) {
  auto args = std::make_shared<SynthArgs>();
  sub.add_option("--out", args->out, "Output CSV (bundle scada.csv columns)")->required();
  app::config::add_drivetrain_option(sub, args->drivetrain);
  sub.add_option("--years", args->years, "Length [years of 365.25 days]")
      ->capture_default_str()
      ->check(app::cli::number_in(0.0, 100.0, "years", true));
  sub.add_option("--period", args->period_s, "Row period [s]")
      ->capture_default_str()
      ->check(app::cli::number_in(0.0, 86400.0, "s", true));
  sub.add_option("--weibull-k", args->weibull_k, "Weibull shape k of the 10-min wind")
      ->capture_default_str()
      ->check(app::cli::positive());
  sub.add_option("--weibull-c", args->weibull_c, "Weibull scale c [m/s]")
      ->capture_default_str()
      ->check(app::cli::positive("m/s"));
  sub.add_option("--lag1", args->lag1,
                 "A single AR(1) with this lag-1 correlation per 10 minutes (the former model; "
                 "default: two-scale persistence fitted to Kelmarsh)")
      ->check(app::cli::number_in(0.0, 1.0, "", true, true));
  sub.add_option("--slow-weight", args->persistence.slow_weight,
                 "Two-scale persistence: variance share of the slow component")
      ->capture_default_str()
      ->check(app::cli::number_in(0.0, 1.0, "", true));
  sub.add_option("--slow-time-constant", args->persistence.slow_time_constant_s,
                 "Two-scale persistence: slow component's time constant [s]")
      ->capture_default_str()
      ->check(app::cli::positive("s"));
  sub.add_option("--fast-lag1", args->persistence.fast_lag1_10min,
                 "Two-scale persistence: fast component's lag-1 correlation per 10 minutes")
      ->capture_default_str()
      ->check(app::cli::number_in(0.0, 1.0, "", false, true));
  sub.add_option("--seasonal-amplitude", args->persistence.seasonal_amplitude,
                 "Annual cycle: relative amplitude of the mean wind (0: none)")
      ->capture_default_str()
      ->check(app::cli::number_in(0.0, 1.0, "", false, true));
  sub.add_option("--seasonal-peak-day", args->persistence.seasonal_peak_day,
                 "Annual cycle: windiest day [days since 1 January]")
      ->capture_default_str()
      ->check(app::cli::number_in(0.0, 366.0, "days", false, true));
  sub.add_option("--diurnal-amplitude", args->persistence.diurnal_amplitude,
                 "Diurnal cycle: relative amplitude of the mean wind (0: none)")
      ->capture_default_str()
      ->check(app::cli::number_in(0.0, 1.0, "", false, true));
  sub.add_option("--diurnal-peak-hour", args->persistence.diurnal_peak_hour,
                 "Diurnal cycle: windiest hour [h UTC]")
      ->capture_default_str()
      ->check(app::cli::number_in(0.0, 24.0, "h", false, true));
  sub.add_flag("--no-progress", args->no_progress, "No progress line on a terminal");
  sub.add_option("--seed", args->seed, "Random seed")
      ->capture_default_str()
      ->check(app::cli::integer_in(0, std::numeric_limits<long long>::max(), "seed"));
  sub.add_option("--start", args->start_s, "First t_s [s since 1970 UTC]")
      ->capture_default_str()
      ->check(app::cli::number_in(app::cli::kInf * -1.0, app::cli::kInf));
  sub.add_option("--days", args->days, "Length [days]; overrides --years")
      ->check(app::cli::number_in(0.0, 36525.0, "days", true));
  sub.add_option("--turbulence", args->turbulence,
                 "Turbulent mode: IEC 61400-1 class A|B|C (I_ref 0.16/0.14/0.12; no default: "
                 "name it), or none (rotor model on the constant means). Rows every --resolution "
                 "s from a rotor model driven by Kaimal turbulence inside each 10-minute mean");
  std::vector<CLI::Option*> turbulent_only;
  turbulent_only.push_back(sub.add_option("--resolution", args->resolution_s,
                                          "Turbulent mode: output row period [s], divides 600")
                               ->capture_default_str()
                               ->check(app::cli::number_in(0.0, 600.0, "s", true)));
  turbulent_only.push_back(sub.add_option(
      "--from-10min", args->from_10min,
      "Turbulent mode: 10-minute mean winds from this SCADA file (bundle or Kelmarsh "
      "columns; builtin:NAME for an embedded file, e.g. builtin:kelmarsh-day.csv)"));
  CLI::Option* mean_wind =
      sub.add_option("--mean-wind", args->mean_wind,
                     "Turbulent mode: constant 10-minute mean wind [m/s] (e.g. 6.75 --days 1)")
          ->check(app::cli::number_in(0.0, 70.0, "m/s", false, true));
  turbulent_only.push_back(mean_wind);
  turbulent_only.push_back(sub.add_option("--hub-height", args->hub_height_m,
                                          "Turbulent mode: hub height [m] (Kaimal length scale)")
                               ->capture_default_str()
                               ->check(app::cli::number_in(0.0, 500.0, "m", true)));
  turbulent_only.push_back(
      sub.add_option("--rotor-inertia", args->rotor_inertia,
                     "Turbulent mode: rotor polar inertia [kg m^2] (assumed, see README)")
          ->capture_default_str()
          ->check(app::cli::positive("kg m^2")));
  turbulent_only.push_back(
      sub.add_option("--step", args->step_s, "Turbulent mode: rotor model time step [s]")
          ->capture_default_str()
          ->check(app::cli::number_in(0.0, 600.0, "s", true)));
  turbulent_only.push_back(sub.add_option("--wind-sample", args->wind_sample_s,
                                          "Turbulent mode: wind series sample period [s]")
                               ->capture_default_str()
                               ->check(app::cli::number_in(0.0, 600.0, "s", true)));
  turbulent_only.push_back(
      sub.add_flag("--point-wind", args->point_wind,
                   "Turbulent mode: the hub point's wind (an upper bound) instead of the "
                   "rotor-effective wind (disc average with IEC 61400-1's exponential coherence)"));
  turbulent_only.push_back(
      sub.add_option("--out-10min", args->out_10min,
                     "Turbulent mode: also write the 10-minute means of the same run here"));
  sub.callback([args, mean_wind, turbulent_only] {
    args->mean_wind_given = mean_wind->count() > 0;
    args->turbulent_only_given.clear();
    for (const CLI::Option* o : turbulent_only) {
      if (o->count() > 0) {
        args->turbulent_only_given = o->get_name();
        break;
      }
    }
    run(*args);
  });
}

const bool kSynthScadaRegistered = app::cli::register_command(
    {"synth-scada",
     "Deterministic synthetic SCADA history (Weibull wind with two-scale persistence, steady-state "
     "turbine; or 1-s rows from turbulent wind through a rotor model, --turbulence)",
     &setup_synth_scada});

}  // namespace
