// `drivetwin run --config FILE [--check-config] [--replay BUNDLE_OR_SCADA [--speed N|max]]`:
// the twin that runs on the box (app/loop/runner.hpp); docs/run.md.
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "bus/bus_config.hpp"
#include "cli/command.hpp"
#include "cli/options.hpp"
#include "config/drivetrain_file.hpp"
#include "loop/runner.hpp"
#include "loop/timing_histogram.hpp"
#include "model/dynamics/rom.hpp"
#include "model/fatigue/drivetrain_channels.hpp"
#include "run/run_config.hpp"

namespace {

using app::cli::CommandError;

struct RunTwinArgs {
  std::string config;
  bool check = false;
  bool reference = false;
  bool print_config = false;
  std::string replay;
  std::string speed;  // "" = max for a replay, real time for simulated buses
  double duration_s = 0.0;
  std::string state_dir;
  std::string json;
  bool lockstep = false;
  bool live_clock = false;
  std::string timing;  // the timing benchmark's report (JSON)
};

std::atomic<bool> g_run_twin_stop{false};
extern "C" void run_twin_on_signal(int) { g_run_twin_stop.store(true); }

double parse_speed(const std::string& s) {
  if (s == "max") return 0.0;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end == s.c_str() || *end != '\0' || !(v > 0.0) || v > 1e6)
    throw CommandError("--speed: expected a factor > 0 (1 = real time) or 'max', got '" + s + "'");
  return v;
}

// --check-config: everything start-up checks without touching the buses.
void check_config(const app::run::RunConfig& c) {
  const model::Drivetrain d = app::config::load_drivetrain(c.drivetrain);
  const app::bus::BusConfig bus = app::bus::load_bus_config(c.bus);
  const model::fatigue::ChannelSet channels(d, model::fatigue::ChannelOptions{});
  if (!channels.valid()) throw CommandError("drivetrain '" + d.name + "': " + channels.error());
  model::dynamics::RomSettings rs;
  rs.dt_s = static_cast<double>(c.period_us) * 1e-6 / static_cast<double>(c.rom_steps_per_cycle);
  rs.cutoff_hz = c.rom_cutoff_hz;
  std::string error;
  model::dynamics::RomBuildReport report;
  if (!model::dynamics::build_rom(d, d.dynamics, rs, &error, &report))
    throw CommandError(c.file.string() +
                       ": loop.rom_steps_per_cycle / loop.rom_cutoff_hz: " + error);
  std::printf("%s: ok\n", c.file.string().c_str());
  std::printf(
      "  drivetrain %s: %zu damage channels; ROM %d modes + %d corrections, step %.3g s "
      "(%.0f Hz)\n",
      d.name.c_str(), channels.channel_count(), report.eigenmodes, report.correction_vectors,
      rs.dt_s, 1.0 / rs.dt_s);
  std::printf("  bus %s: scada %s, cms %s, keyphasor %s, outputs %s, results %s\n",
              bus.file.string().c_str(), app::bus::to_string(bus.scada),
              app::bus::to_string(bus.cms), app::bus::to_string(bus.keyphasor),
              app::bus::to_string(bus.outputs), app::bus::to_string(bus.results));
  std::printf("  state folder %s\n", c.state_dir.c_str());
  std::fputs(app::run::describe(c).c_str(), stdout);
}

void write_summary(const app::loop::RunSummary& s, const std::string& json_file) {
  std::printf(
      "# drivetwin run: %.1f s of loop time in %.2f s wall (%.1f × real time); %llu "
      "cycles, %llu overruns, %llu ROM steps; calibration generation %u\n",
      s.loop_time_s, s.wall_time_s, s.wall_time_s > 0 ? s.loop_time_s / s.wall_time_s : 0.0,
      static_cast<unsigned long long>(s.last.counters.cycles),
      static_cast<unsigned long long>(s.last.counters.overruns),
      static_cast<unsigned long long>(s.last.counters.rom_steps), s.calibration_generation);
  std::printf("%-40s %14s %14s\n", "channel", "damage", "rul_h");
  for (std::size_t c = 0; c < s.damage.size(); ++c) {
    std::printf("%-40s %14.6e %14.6e\n", s.channel_names[c].c_str(), s.damage[c],
                static_cast<double>(s.last.channels[c].rul_h));
  }
  if (json_file.empty()) return;
  nlohmann::json j;
  j["loop_time_s"] = s.loop_time_s;
  j["wall_time_s"] = s.wall_time_s;
  j["elapsed_s"] = s.elapsed_s;
  j["cycles"] = s.last.counters.cycles;
  j["overruns"] = s.last.counters.overruns;
  j["rom_steps"] = s.last.counters.rom_steps;
  j["rom_adoptions"] = s.last.counters.rom_adoptions;
  j["calibration_generation"] = s.calibration_generation;
  j["status_word"] = s.last.status_word;
  j["fault_word"] = s.last.fault_word;
  j["restored"] = s.restored;
  j["memory_locked"] = s.memory_locked;
  j["rt_thread_warning"] = s.rt_thread_warning;
  for (std::size_t c = 0; c < s.damage.size(); ++c)
    j["channels"].push_back({{"name", s.channel_names[c]}, {"damage", s.damage[c]}});
  std::ofstream out(json_file);
  if (!out) throw CommandError("--json: cannot write " + json_file);
  out << j.dump(2) << '\n';
}

// --timing: the loop's wake-up latency and cycle time distribution, overruns and the RT
// thread's CPU share (the timing benchmark, tools/rt_bench/run.sh).
void write_timing(const app::loop::TimingHistogram& t, const app::loop::RunSummary& s,
                  const app::run::RunConfig& c, const std::string& file) {
  const double period_us = static_cast<double>(c.period_us);
  nlohmann::json j;
  j["period_us"] = period_us;
  j["cycles"] = t.cycles();
  j["loop_time_s"] = s.loop_time_s;
  j["wall_time_s"] = s.wall_time_s;
  j["rt_cpu_s"] = s.rt_cpu_s;
  j["rt_cpu_share"] = s.loop_time_s > 0.0 ? s.rt_cpu_s / s.loop_time_s : 0.0;
  j["rt_thread_warning"] = s.rt_thread_warning;
  j["memory_locked"] = s.memory_locked;
  j["overruns"] = s.last.counters.overruns;
  j["late_by_more_than_period"] = t.latency_above(period_us);
  for (const auto& [name, q] : {std::pair<const char*, double>{"p50", 0.5},
                                {"p99", 0.99},
                                {"p99_9", 0.999},
                                {"max", 1.0}}) {
    j["latency_us"][name] = t.latency_quantile_us(q);
    j["cycle_us"][name] = t.cycle_quantile_us(q);
  }
  std::ofstream out(file);
  if (!out) throw CommandError("--timing: cannot write " + file);
  out << j.dump(2) << '\n';
}

void run_twin_command(const RunTwinArgs& a) {
  if (a.reference) {
    std::fputs(app::run::run_config_reference().c_str(), stdout);
    return;
  }
  if (a.config.empty()) throw CommandError("--config FILE is required");
  app::run::RunConfig c;
  try {
    c = app::run::load_run_config(a.config);
  } catch (const app::run::RunConfigError& e) {
    throw CommandError(e.what());
  }
  if (!a.state_dir.empty()) c.state_dir = a.state_dir;
  if (a.check) {
    check_config(c);
    return;
  }
  app::loop::RunOptions o;
  o.replay = a.replay;
  o.speed = parse_speed(a.speed.empty() ? (a.replay.empty() ? "1" : "max") : a.speed);
  o.duration_s = a.duration_s;
  o.print_config = a.print_config;
  o.lockstep = a.lockstep;
  o.live_clock = a.live_clock;
  std::unique_ptr<app::loop::TimingHistogram> timing;
  if (!a.timing.empty()) {
    timing = std::make_unique<app::loop::TimingHistogram>();
    o.timing = timing.get();
  }
  g_run_twin_stop = false;
  o.stop = &g_run_twin_stop;
  struct sigaction sa {};
  sa.sa_handler = run_twin_on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGTERM, &sa, nullptr);
  sigaction(SIGINT, &sa, nullptr);
  app::loop::RunSummary s;
  try {
    s = app::loop::run_twin(c, o);
  } catch (const app::bus::BusConfigError& e) {
    throw CommandError(e.what());
  } catch (const std::runtime_error& e) {
    throw CommandError(e.what());
  }
  write_summary(s, a.json);
  if (timing) write_timing(*timing, s, c, a.timing);
}

void setup_run_twin(CLI::App& sub) {
  auto a = std::make_shared<RunTwinArgs>();
  sub.add_option("--config", a->config,
                 "run configuration (TOML, drivetwin-run/1; docs/run.md), e.g. "
                 "app/data/run/twin-paper-2mw.toml");
  sub.add_flag("--check-config", a->check,
               "validate the configuration, the bus file and the drivetrain (builds the ROM), "
               "print the effective values and exit");
  sub.add_flag("--config-reference", a->reference,
               "print every parameter (key, type, default, range, unit, description) as Markdown");
  sub.add_flag("--print-config", a->print_config, "log the effective configuration at start");
  sub.add_option("--replay", a->replay,
                 "replay a recording bundle (SCADA, CMS, keyphasor) or a SCADA CSV / builtin:NAME "
                 "(SCADA only; the other buses as the bus file says) on the recording's clock");
  sub.add_option("--speed", a->speed,
                 "replay / simulated buses: recording seconds per wall second (1 = real time) or "
                 "'max' (default: max for --replay, 1 for simulated buses)")
      ->check(app::cli::number_in_or_word("max", 0.0, 1e6, "", true));
  sub.add_option("--duration", a->duration_s,
                 "stop after this much loop time [s] (0: never / "
                 "the end of the replay)")
      ->check(app::cli::number_in(0.0, 1e9, "s"));
  sub.add_option("--state-dir", a->state_dir, "override twin.state_dir");
  sub.add_flag("--lockstep", a->lockstep,
               "replay / simulated buses: wait for the calibration thread at each window, so "
               "that the run, calibration included, repeats bit for bit");
  sub.add_flag("--live-clock", a->live_clock,
               "simulated buses: run on the live clock as in the cabinet (absolute deadlines on "
               "CLOCK_MONOTONIC, missed periods skipped) instead of stepped time paced at "
               "--speed; the timing benchmark uses it");
  sub.add_option("--json", a->json, "write a JSON summary (damage per channel, counters)");
  sub.add_option("--timing", a->timing,
                 "write the loop's timing (wake-up latency and cycle time p50/p99/p99.9/max, "
                 "overruns, the RT thread's CPU share) as JSON: the timing benchmark, "
                 "tools/rt_bench/run.sh");
  sub.callback([a] { run_twin_command(*a); });
}

const bool kRunTwinRegistered = app::cli::register_command(
    {"run",
     "Run the twin: the real-time loop on the turbine bus (or a replay), calibration, damage",
     &setup_run_twin});

}  // namespace
