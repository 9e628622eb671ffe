// `drivetwin run`'s composition: see runner.hpp.
#include "loop/runner.hpp"

#include <pthread.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>

#include "bus/bus_config.hpp"
#include "config/drivetrain_file.hpp"
#include "data/embedded.hpp"
#include "hal/gpiod_lines.hpp"
#include "hal/memory_backends.hpp"
#include "hal/modbus_results_server.hpp"
#include "hal/modbus_scada_source.hpp"
#include "hal/recording_bundle.hpp"
#include "hal/replay_backends.hpp"
#include "hal/scada_csv.hpp"
#include "hal/sim_backends.hpp"
#include "hal/socketcan_cms_stream.hpp"
#include "hal/thread.hpp"
#include "loop/calibration_worker.hpp"
#include "loop/cycle_clock.hpp"
#include "loop/events.hpp"
#include "loop/timing_histogram.hpp"
#include "loop/twin.hpp"
#include "model/fatigue/rul.hpp"
#include "persistence/twin_persistence.hpp"
#include "trends/trends_writer.hpp"

namespace app::loop {
namespace fs = std::filesystem;
using bus::Backend;
using run::ThreadId;

namespace {

[[noreturn]] void fail(const std::string& m) { throw std::runtime_error(m); }

void check(hal::Status s, const std::string& what) {
  if (s != hal::Status::kOk) fail(what + ": " + hal::to_string(s));
}

// Serialises the non-RT threads' writes to the log stream.
class LogSink {
 public:
  explicit LogSink(std::ostream& out) : out_(out) {}
  void line(const std::string& s) {
    if (s.empty()) return;
    const std::lock_guard<std::mutex> lock(mutex_);
    out_ << s << '\n';
    out_.flush();
  }

 private:
  std::ostream& out_;
  std::mutex mutex_;
};

// "builtin:NAME" → a temporary copy of the embedded file (removed at the end of the run).
struct TempFile {
  std::string path;
  ~TempFile() {
    if (!path.empty()) {
      std::error_code ec;
      fs::remove(path, ec);
    }
  }
};

std::string materialise(const std::string& name, TempFile& temp) {
  const std::string prefix = "builtin:";
  if (name.rfind(prefix, 0) != 0) return name;
  const auto text = data::embedded_file(name.substr(prefix.size()));
  if (!text) {
    std::string names;
    for (const auto& n : data::embedded_file_names()) names += (names.empty() ? "" : ", ") + n;
    fail("--replay " + name + ": no embedded data file (have: " + names + ")");
  }
  std::string tmpl = (fs::temp_directory_path() / "drivetwin-replay-XXXXXX").string();
  const int fd = mkstemp(tmpl.data());
  if (fd < 0) fail("cannot create a temporary copy of " + name);
  const ssize_t n = ::write(fd, text->data(), text->size());
  ::close(fd);
  temp.path = tmpl;
  if (n != static_cast<ssize_t>(text->size())) fail("cannot write a temporary copy of " + name);
  return tmpl;
}

// The SCADA rows' period: the median spacing of the first rows' times [s] (0: unknown).
double scada_period_s(const std::string& csv, const hal::ScadaColumns& columns) {
  hal::ScadaCsvReader r;
  if (!r.open(csv, columns)) return 0.0;
  std::vector<double> dt;
  hal::ScadaRow row;
  double prev = std::nan("");
  while (dt.size() < 1000 && r.next(row) == hal::ScadaReadResult::kRow) {
    const double t = row.time_s();
    if (std::isnan(t)) continue;
    if (!std::isnan(prev) && t > prev) dt.push_back(t - prev);
    prev = t;
  }
  if (dt.empty()) return 0.0;
  std::nth_element(dt.begin(), dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2), dt.end());
  return dt[dt.size() / 2];
}

std::optional<hal::ScadaColumns> columns_for(const std::string& csv, std::string& chosen) {
  // auto: the bundle's own columns if the file has them, else Kelmarsh's export.
  for (const char* spec : {"bundle", "kelmarsh"}) {
    std::string err;
    const auto cols = hal::parse_scada_columns(spec, &err);
    if (!cols) continue;
    hal::ScadaCsvReader r;
    if (r.open(csv, *cols)) {
      hal::ScadaRow row;
      if (r.next(row) == hal::ScadaReadResult::kRow && !std::isnan(row.time_s())) {
        chosen = spec;
        return cols;
      }
    }
  }
  return std::nullopt;
}

std::string channel_name(const model::fatigue::Channel& c) {
  std::string s = c.component;
  if (!c.detail.empty()) s += "/" + c.detail;
  return s + "/" + model::fatigue::failure_mode_name(c.mode);
}

// Locks the process's memory: MCL_FUTURE too only when the limit allows it (otherwise
// later allocations of the non-RT threads would fail beyond RLIMIT_MEMLOCK).
bool lock_memory(std::string& note) {
  rlimit lim{};
  const bool unlimited = getrlimit(RLIMIT_MEMLOCK, &lim) == 0 && lim.rlim_cur == RLIM_INFINITY;
  const int flags = unlimited ? (MCL_CURRENT | MCL_FUTURE) : MCL_CURRENT;
  if (mlockall(flags) != 0) {
    note = std::string("mlockall refused (") + std::strerror(errno) +
           "): memory not locked, page faults may delay the RT thread (raise RLIMIT_MEMLOCK "
           "or grant CAP_IPC_LOCK)";
    return false;
  }
  if (!unlimited)
    note =
        "memory locked as allocated now (MCL_CURRENT); RLIMIT_MEMLOCK is finite, so later "
        "allocations of non-RT threads are not locked";
  return true;
}

// Touches the RT thread's stack so that its pages are resident before the first cycle: half
// the configured size, at most 192 KiB, and never closer than 32 KiB to the stack's end as
// the thread finds it (glibc puts static TLS inside the thread's stack: ThreadSanitizer's
// per-thread state took enough of a 256 KiB stack that a fixed 192 KiB buffer overran it).
void prefault_stack(std::size_t bytes) {
  constexpr std::size_t kMax = 192 * 1024, kMargin = 32 * 1024;
  std::size_t n = std::min(bytes / 2, kMax);
  pthread_attr_t attr;
  if (pthread_getattr_np(pthread_self(), &attr) == 0) {
    void* low = nullptr;
    std::size_t size = 0;
    if (pthread_attr_getstack(&attr, &low, &size) == 0) {
      const auto here = reinterpret_cast<std::uintptr_t>(__builtin_frame_address(0));
      const auto end = reinterpret_cast<std::uintptr_t>(low);
      const std::size_t free = here > end + kMargin ? here - end - kMargin : 0;
      n = std::min(n, free);
    }
    pthread_attr_destroy(&attr);
  }
  if (n == 0) return;
  auto* buf = static_cast<volatile unsigned char*>(__builtin_alloca(n));
  for (std::size_t i = 0; i < n; i += 4096) buf[i] = 0;
  asm volatile("" : : "r"(buf) : "memory");  // keep the touched buffer
}

}  // namespace

RunSummary run_twin(const run::RunConfig& cfg, const RunOptions& opt) {
  std::ostream& out = opt.log ? *opt.log : std::cerr;
  LogSink log(out);
  RunSummary summary;
  const auto wall_start = std::chrono::steady_clock::now();

  // ---- configuration, description, wiring ----
  const model::Drivetrain drivetrain = config::load_drivetrain(cfg.drivetrain);
  bus::BusConfig bc = bus::load_bus_config(cfg.bus);
  model::fatigue::ChannelSet channels(drivetrain, model::fatigue::ChannelOptions{});
  if (!channels.valid()) fail("drivetrain '" + drivetrain.name + "': " + channels.error());

  const bool replay = !opt.replay.empty();
  TempFile temp;
  std::optional<hal::Recording> rec;
  std::string replay_csv;
  hal::ScadaColumns replay_columns;
  double replay_end_s = 0.0;
  TwinSettings ts;
  ts.cms_sample_rate_hz = cfg.cms_sample_rate_hz;
  if (replay) {
    std::error_code ec;
    if (fs::is_directory(opt.replay, ec)) {
      auto r = hal::read_bundle(opt.replay);
      if (!r.recording) fail("--replay " + opt.replay + ": " + r.error.to_string());
      rec = std::move(*r.recording);
      if (rec->scada.empty()) {
        // No scada.csv: the recording's mean operating point (recording-bundle.md) as 1 Hz
        // SCADA rows over the recording.
        const double seconds = static_cast<double>(rec->sample_count()) / rec->sample_rate_hz;
        const hal::BundleOperatingPoint& op = rec->operating_point;
        for (double t = 0.0; t <= seconds; t += 1.0) {
          hal::BundleScadaRow row;
          row.t_s = t;
          row.wind_speed_mps = op.wind_speed_mps.value_or(0.0);
          row.rotor_speed_rpm = op.rotor_speed_rpm;
          row.torque_nm = op.input_torque_nm;
          rec->scada.push_back(row);
        }
        log.line("drivetwin run: " + opt.replay +
                 ": no scada.csv; the recording's operating point is replayed as SCADA");
      }
      bc.scada = Backend::kReplay;
      bc.cms = Backend::kReplay;
      bc.keyphasor = Backend::kReplay;
      ts.cms_sample_rate_hz = rec->sample_rate_hz;
      replay_end_s = static_cast<double>(rec->samples.empty() ? 0 : rec->samples[0].size()) /
                     rec->sample_rate_hz;
    } else {
      replay_csv = materialise(opt.replay, temp);
      if (!fs::exists(replay_csv, ec)) fail("--replay " + opt.replay + ": no such file or folder");
      std::string chosen;
      const auto cols = columns_for(replay_csv, chosen);
      if (!cols)
        fail("--replay " + opt.replay +
             ": neither bundle nor Kelmarsh columns with a time stamp found in the header");
      replay_columns = *cols;
      bc.scada = Backend::kReplay;
    }
    // A replay never drives the cabinet's relays.
    if (bc.outputs == Backend::kLinux) bc.outputs = Backend::kSim;
  }
  // UTC time of loop time 0, for the trends' clock-aligned intervals: a replay's first row
  // (a CSV with dates) or its bundle's start; live, the wall clock at start (to the start-up's
  // fraction of a second).
  double trends_origin_unix_s =
      std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  if (replay) {
    trends_origin_unix_s = 0.0;
    if (rec) {
      if (const auto t = hal::parse_utc_datetime_s(rec->start_utc)) trends_origin_unix_s = *t;
    } else {
      hal::ScadaCsvReader r;
      hal::ScadaRow row;
      if (r.open(replay_csv, replay_columns) && r.next(row) == hal::ScadaReadResult::kRow &&
          row.has_time())
        trends_origin_unix_s = row.time_s();
    }
  }
  const bool stepped = replay || (!opt.live_clock && bc.scada != Backend::kLinux &&
                                  bc.cms != Backend::kLinux && bc.keyphasor != Backend::kLinux);

  // ---- persisted state ----
  std::error_code ec;
  fs::create_directories(cfg.state_dir, ec);
  const bool state_ok = !ec && fs::is_directory(cfg.state_dir, ec);
  if (!state_ok)
    log.line("drivetwin run: WARN: state folder " + cfg.state_dir +
             " cannot be created: damage and calibration will not be saved");
  const std::string calibration_file = (fs::path(cfg.state_dir) / "calibration.txt").string();
  // The damage, RUL rate history and a copy of the calibration: the two-copy crash-safe store
  // (persistence/twin_persistence.hpp), carried over a change of ROM rate or channel set.
  model::fatigue::AccumulatorConfig accumulator_cfg;
  accumulator_cfg.tick_s =
      static_cast<double>(cfg.period_us) * 1e-6 / static_cast<double>(cfg.rom_steps_per_cycle);
  accumulator_cfg.bins = static_cast<std::uint32_t>(cfg.bins);
  persistence::TwinPersistence store(
      {cfg.state_dir, state_ok ? calibration_file : "", cfg.rul_interval_s,
       static_cast<std::size_t>(cfg.rul_short_window)},
      channels, accumulator_cfg);
  persistence::TwinLoad loaded;
  if (state_ok) {
    loaded = store.load();
    for (const std::string& line : loaded.lines) log.line("drivetwin run: " + line);
  }
  model::DynamicsParameters parameters = drivetrain.dynamics;
  std::uint32_t generation = 0;
  {
    std::string probe_error;
    std::uint32_t probe_generation = 0;
    if (loaded.calibration &&
        !load_calibration(calibration_file, drivetrain.dynamics, &probe_generation, &probe_error)) {
      // The calibration file is missing or corrupt; the state record holds its last copy.
      std::ofstream(calibration_file, std::ios::binary | std::ios::trunc)
          << loaded.calibration->text;
      log.line("drivetwin run: " +
               std::string(probe_error.empty() ? "" : "WARN: " + probe_error + "; ") +
               "calibration restored from the state record into " + calibration_file);
    }
  }
  {
    std::string error;
    if (auto p = load_calibration(calibration_file, drivetrain.dynamics, &generation, &error)) {
      parameters = *p;
      log.line("drivetwin run: calibrated parameters of generation " + std::to_string(generation) +
               " loaded from " + calibration_file);
    } else if (!error.empty()) {
      log.line("drivetwin run: WARN: " + error);
    }
  }

  // ---- model ----
  ts.period_ns = cfg.period_us * 1000;
  ts.rom_steps_per_cycle = static_cast<int>(cfg.rom_steps_per_cycle);
  model::dynamics::RomSettings rs;
  rs.dt_s = static_cast<double>(ts.period_ns) * 1e-9 / static_cast<double>(ts.rom_steps_per_cycle);
  rs.cutoff_hz = cfg.rom_cutoff_hz;
  std::string error;
  std::unique_ptr<model::dynamics::RomData> rom =
      model::dynamics::build_rom(drivetrain, parameters, rs, &error);
  if (!rom) fail("drivetrain '" + drivetrain.name + "': reduced-order model: " + error);
  if (opt.on_rom_built) opt.on_rom_built(*rom);

  // ---- twin settings ----
  ts.publish_divisor = static_cast<int>(cfg.publish_divisor);
  ts.point_channel = {static_cast<int>(cfg.point1_channel), static_cast<int>(cfg.point2_channel)};
  ts.zones = {cfg.accel_hf_bc_mps2, cfg.accel_hf_cd_mps2, cfg.velocity_bc_mmps,
              cfg.velocity_cd_mmps, cfg.accel_lf_bc_mps2, cfg.accel_lf_cd_mps2,
              cfg.hf_interval_s,    cfg.lf_interval_s};
  ts.supervisor.torque = static_cast<wind::TorquePreference>(cfg.torque_source);
  ts.supervisor.hold_s = cfg.scada_hold_s;
  ts.supervisor.alarm_zone = cfg.alarm_zone == 0 ? VibrationZone::kD : VibrationZone::kC;
  ts.calibration_enabled = cfg.calibration_enabled;
  ts.window_s = cfg.window_s;
  ts.check_interval_s = cfg.check_interval_s;
  ts.steady_speed_tolerance = cfg.steady_speed_tolerance;
  ts.steady_torque_tolerance = cfg.steady_torque_tolerance;
  ts.rul_interval_s = cfg.rul_interval_s;
  ts.checkpoint_interval_s = cfg.checkpoint_interval_s;
  ts.accumulator_bins = static_cast<std::uint32_t>(cfg.bins);

  // ---- devices: construct (no I/O) ----
  hal::ManualClock manual_clock;
  // Live: the backends stamp on the loop's time base (CLOCK_MONOTONIC from this origin),
  // which the cycle clock counts `now` from (a backend comparing the loop's `now` with its own
  // stamps — the sim source's schedule, SCADA ages — needs both on one base).
  LoopTimeClock live_clock(CycleClock::monotonic_ns());
  const hal::Clock& clock = stepped ? static_cast<const hal::Clock&>(manual_clock)
                                    : static_cast<const hal::Clock&>(live_clock);
  bc.modbus_client.thread = cfg.thread(ThreadId::kScadaIo);
  bc.socketcan.thread = cfg.thread(ThreadId::kCmsIo);
  bc.gpio_keyphasor.thread = cfg.thread(ThreadId::kKeyphasorIo);
  bc.modbus_server.thread = cfg.thread(ThreadId::kResultsServer);
  const results::RegisterMap results_map(channels, bc.modbus_server.word_order);

  std::unique_ptr<hal::ScadaSource> scada;
  switch (bc.scada) {
    case Backend::kLinux:
      scada = std::make_unique<hal::ModbusScadaSource>(bc.modbus_client, clock);
      ts.scada_period_s = std::chrono::duration<double>(bc.modbus_client.poll_period).count();
      break;
    case Backend::kReplay:
      if (!replay_csv.empty()) {
        scada = std::make_unique<hal::ReplayScadaSource>(replay_csv, replay_columns);
        const double period = scada_period_s(replay_csv, replay_columns);
        if (period > 0.0) ts.scada_period_s = period;
        auto* r = static_cast<hal::ReplayScadaSource*>(scada.get());
        check(r->configure(), "--replay " + opt.replay + ": " + r->error());
        replay_end_s = std::chrono::duration<double>(r->duration()).count() + period;
      } else if (rec) {
        scada = std::make_unique<hal::ReplayScadaSource>(rec->scada);
        if (rec->scada.size() >= 2)
          ts.scada_period_s = (rec->scada.back().t_s - rec->scada.front().t_s) /
                              static_cast<double>(rec->scada.size() - 1);
      } else if (!bc.scada_csv.empty()) {
        std::string err;
        const auto cols = hal::parse_scada_columns(bc.scada_columns, &err);
        if (!cols) fail(bc.file.string() + ": scada.columns: " + err);
        scada = std::make_unique<hal::ReplayScadaSource>(bc.scada_csv, *cols);
      } else {
        fail(bc.file.string() + ": scada.backend = \"replay\" needs --replay or scada.csv");
      }
      break;
    case Backend::kSim: {
      const hal::SimScadaConfig sim = hal::sim_scada_paper_point();
      ts.scada_period_s = std::chrono::duration<double>(sim.period).count();
      auto s = std::make_unique<hal::SimScadaSource>(sim, clock);
      s->inject(bc.scada_fault);
      scada = std::move(s);
      break;
    }
    case Backend::kNone:
      break;
  }
  if (!scada) fail(bc.file.string() + ": the twin needs a SCADA source (scada.backend)");

  std::unique_ptr<hal::CmsStream> cms;
  switch (bc.cms) {
    case Backend::kLinux:
      cms = std::make_unique<hal::SocketCanCmsStream>(bc.socketcan, clock);
      break;
    case Backend::kReplay: {
      if (!rec) fail(bc.file.string() + ": cms.backend = \"replay\" needs --replay BUNDLE");
      auto r = std::make_unique<hal::ReplayCmsStream>(*rec, clock);
      check(r->configure(), opt.replay + ": CMS replay");
      // Points by the drivetrain's measurement-point channel names.
      for (std::size_t p = 0; p < kSnapshotPoints && p < drivetrain.measurement_points.size();
           ++p) {
        bool found = false;
        for (std::size_t k = 0; k < r->channels(); ++k) {
          if (rec->channels[r->source_channel(static_cast<std::uint8_t>(k))].name ==
              drivetrain.measurement_points[p].channel) {
            ts.point_channel[p] = static_cast<int>(k);
            found = true;
          }
        }
        if (!found)
          fail(opt.replay + ": no channel named '" + drivetrain.measurement_points[p].channel +
               "' (measurement point " + std::to_string(p + 1) + ")");
      }
      cms = std::move(r);
      break;
    }
    case Backend::kSim: {
      hal::SimCmsConfig sc;
      sc.sample_rate_hz = cfg.cms_sample_rate_hz;
      auto s = std::make_unique<hal::SimCmsStream>(sc, clock);
      s->inject(bc.cms_fault);
      cms = std::move(s);
      break;
    }
    case Backend::kNone:
      break;
  }
  std::unique_ptr<hal::Keyphasor> keyphasor;
  switch (bc.keyphasor) {
    case Backend::kLinux:
      keyphasor = std::make_unique<hal::GpiodKeyphasor>(bc.gpio_keyphasor);
      break;
    case Backend::kReplay:
      if (!rec) fail(bc.file.string() + ": keyphasor.backend = \"replay\" needs --replay BUNDLE");
      keyphasor = std::make_unique<hal::ReplayKeyphasor>(*rec, clock);
      break;
    case Backend::kSim: {
      auto s = std::make_unique<hal::SimKeyphasor>(hal::SimKeyphasorConfig{}, clock);
      s->inject(bc.keyphasor_fault);
      keyphasor = std::move(s);
      break;
    }
    case Backend::kNone:
      break;
  }
  std::unique_ptr<hal::DigitalOutputs> outputs;
  if (bc.outputs == Backend::kLinux)
    outputs = std::make_unique<hal::GpiodDigitalOutputs>(bc.gpio_outputs);
  if (bc.outputs == Backend::kSim) outputs = std::make_unique<hal::MemoryDigitalOutputs>();
  std::unique_ptr<hal::ResultsSink> results;
  if (bc.results == Backend::kLinux) {
    hal::ModbusServerConfig sc = bc.modbus_server;
    sc.register_count = results_map.register_count();
    results = std::make_unique<hal::ModbusResultsServer>(sc);
  }

  // ---- configure + activate (I/O threads start here, from the thread table) ----
  const std::string f = bc.file.string();
  if (scada->state() == hal::LifecycleState::kUnconfigured)
    check(scada->configure(), f + ": scada (" + bus::to_string(bc.scada) + ")");
  if (cms && cms->state() == hal::LifecycleState::kUnconfigured)
    check(cms->configure(), f + ": cms (" + bus::to_string(bc.cms) + ")");
  if (keyphasor)
    check(keyphasor->configure(), f + ": keyphasor (" + bus::to_string(bc.keyphasor) + ")");
  if (outputs) check(outputs->configure(), f + ": outputs");
  if (results) {
    check(results->configure(), f + ": results (" + bc.modbus_server.bind_address + ":" +
                                    std::to_string(bc.modbus_server.port) + ")");
  }
  check(scada->activate(), f + ": scada activate");
  if (cms) check(cms->activate(), f + ": cms activate");
  if (keyphasor) check(keyphasor->activate(), f + ": keyphasor activate");
  if (outputs) check(outputs->activate(), f + ": outputs activate");
  if (results) check(results->activate(), f + ": results activate");

  // ---- the twin and its mailboxes ----
  auto mail = std::make_unique<Mailboxes>();
  std::vector<std::unique_ptr<CmsWindow>> windows;
  const auto window_samples =
      static_cast<std::size_t>(std::ceil(cfg.window_s * ts.cms_sample_rate_hz));
  for (std::size_t i = 0; i < Mailboxes::kWindows; ++i) {
    windows.push_back(std::make_unique<CmsWindow>());
    for (auto& s : windows.back()->samples) s.assign(window_samples, 0.0);
    // Keyphasor edges in a window: up to the tracker's fastest plausible shaft (200 Hz).
    windows.back()->pulses_s.assign(static_cast<std::size_t>(std::ceil(cfg.window_s * 200.0)) + 8,
                                    0.0);
    (void)mail->windows_free.push(windows.back().get());
  }
  std::vector<std::unique_ptr<model::fatigue::AccumulatorState>> checkpoints;
  for (std::size_t i = 0; i < Mailboxes::kCheckpoints; ++i) {
    checkpoints.push_back(std::make_unique<model::fatigue::AccumulatorState>());
    (void)mail->checkpoints_free.push(checkpoints.back().get());
  }
  const TwinDevices devices{scada.get(), cms.get(), keyphasor.get(), outputs.get(), results.get()};
  if (opt.on_devices) opt.on_devices(devices);
  // From here the RT thread owns the running model (handed back through the mailbox when a
  // calibrated one replaces it, freed by the calibration thread).
  model::dynamics::RomData* initial_rom = rom.release();
  auto twin = std::make_unique<Twin>(drivetrain, channels, *initial_rom, ts, *mail, devices);
  twin->set_calibration_generation(static_cast<std::uint16_t>(generation));
  summary.calibration_generation = generation;
  if (loaded.restored) {
    summary.restored = twin->restore(*loaded.accumulator);
    if (!summary.restored)
      log.line("drivetwin run: ERR: the restored damage does not fit the running accumulator");
  }
  CalibrationWorkerSettings cws;
  cws.method =
      static_cast<model::calibration::CalibrationMethod>(cfg.calibration_method == 0   ? 2
                                                         : cfg.calibration_method == 1 ? 1
                                                                                       : 0);
  cws.max_evaluations = static_cast<std::size_t>(cfg.max_evaluations);
  cws.space = cfg.calibration_space == 1 ? WorkerSpace::kPaper : WorkerSpace::kStandard;
  cws.rom = rs;
  cws.state_file = state_ok ? calibration_file : "";
  cws.diagnosis = cfg.diagnosis_enabled;
  cws.diagnosis_interval_s = cfg.diagnosis_interval_s;
  std::unique_ptr<CalibrationWorker> calibration;
  if (cfg.calibration_enabled && cms) {
    calibration =
        std::make_unique<CalibrationWorker>(drivetrain, parameters, cws, *mail, generation);
  }
  if (calibration) calibration->set_note([&log](const std::string& s) { log.line(s); });
  for (std::size_t c = 0; c < channels.channel_count(); ++c)
    summary.channel_names.push_back(channel_name(channels.channel(c)));

  // ---- memory ----
  std::string lock_note;
  summary.memory_locked = lock_memory(lock_note);
  if (!lock_note.empty())
    log.line("drivetwin run: " + std::string(summary.memory_locked ? "" : "WARN: ") + lock_note);
  if (opt.print_config) log.line(run::describe(cfg));

  // ---- threads ----
  std::atomic<bool> workers_stop{false};
  std::atomic<bool> persistence_failed{false};
  std::atomic<bool> trends_stop{false};
  std::atomic<std::int64_t> last_now_ns{0};  // [ns] the loop's time, for the state record
  hal::Thread service_thread, persistence_thread, trends_thread, calibration_thread, rt_thread;
  const auto start_thread = [&](hal::Thread& t, ThreadId id, std::function<void()> body) {
    const hal::Status s = t.start(cfg.thread(id), std::move(body));
    if (s != hal::Status::kOk)
      fail(std::string("cannot start thread ") + cfg.thread(id).name + ": " + hal::to_string(s));
    if (!t.report().warning.empty()) log.line("drivetwin run: WARN: " + t.report().warning);
  };

  EventLog event_log(static_cast<std::int64_t>(cfg.log_interval_s * 1e9));
  start_thread(service_thread, ThreadId::kLog, [&] {
    RulTable table;
    table.rul_low_h.fill(kNoValue);
    std::vector<double> interval_damage(channels.channel_count(), 0.0);
    for (;;) {
      bool idle = true;
      Event e;
      while (mail->events.pop(e)) {
        log.line(event_log.format(e));
        idle = false;
      }
      if (calibration) {
        while (calibration->events().pop(e)) {
          log.line(event_log.format(e));
          idle = false;
        }
      }
      IntervalRecord r;
      while (mail->intervals.pop(r)) {
        for (std::size_t c = 0; c < r.channel_count && c < interval_damage.size(); ++c)
          interval_damage[c] = r.damage[c];
        // The rate history lives with the persisted state (saved with every checkpoint).
        const std::vector<double> rul_low_h = store.add_interval(interval_damage);
        for (std::size_t c = 0; c < rul_low_h.size() && c < table.rul_low_h.size(); ++c)
          table.rul_low_h[c] = static_cast<float>(rul_low_h[c]);
        ++table.intervals;
        mail->rul.write(table);
        idle = false;
      }
      if (idle) {
        if (workers_stop.load()) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
    }
  });
  start_thread(persistence_thread, ThreadId::kPersistence, [&] {
    for (;;) {
      model::fatigue::AccumulatorState* s = nullptr;
      if (mail->checkpoints_full.pop(s)) {
        std::string err;
        const bool saved = state_ok && store.save(*s, last_now_ns.load(), &err);
        if (state_ok && !saved) {
          if (!persistence_failed.exchange(true))
            log.line("drivetwin run: WARN: checkpoint: " + err);
          mail->persistence_failed.store(true, std::memory_order_relaxed);
        } else if (saved && persistence_failed.exchange(false)) {
          log.line("drivetwin run: checkpoint saved again (" +
                   store.store().copy_path(0).parent_path().string() + ")");
          mail->persistence_failed.store(false, std::memory_order_relaxed);
        }
        (void)mail->checkpoints_free.push(s);
        continue;
      }
      if (workers_stop.load()) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  });
  // Trends: the snapshots into SQLite (trends/trends_writer.hpp) on their own thread.
  std::unique_ptr<trends::TrendsWriter> trends_writer;
  if (state_ok) {
    trends::TrendsSettings tw;
    tw.path = (fs::path(cfg.state_dir) / "trends.db").string();
    tw.drivetrain = drivetrain.name;
    tw.origin_unix_s = trends_origin_unix_s;
    for (std::size_t c = 0; c < channels.channel_count(); ++c)
      tw.channel_keys.push_back(persistence::channel_key(channels.channel(c)));
    std::string err;
    trends_writer = trends::TrendsWriter::open(tw, &err);
    if (!trends_writer) log.line("drivetwin run: WARN: " + err + "; no trends are written");
  }
  start_thread(trends_thread, ThreadId::kTrends, [&] {
    Snapshot snap;
    std::uint64_t errors = 0;
    for (;;) {
      bool idle = true;
      while (mail->snapshots.pop(snap)) {
        if (trends_writer) trends_writer->add(snap);
        idle = false;
      }
      if (trends_writer && trends_writer->stats().errors > errors) {
        errors = trends_writer->stats().errors;
        log.line("drivetwin run: WARN: trends: " + trends_writer->stats().last_error);
      }
      if (idle) {
        if (trends_stop.load()) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
    }
    if (trends_writer) trends_writer->flush();
  });
  if (calibration)
    start_thread(calibration_thread, ThreadId::kCalibration, [&] { calibration->run(); });

  const std::int64_t end_ns =
      opt.duration_s > 0.0
          ? static_cast<std::int64_t>(opt.duration_s * 1e9)
          : (replay && replay_end_s > 0.0 ? static_cast<std::int64_t>(replay_end_s * 1e9) : 0);
  hal::Timestamp last_now{0};
  start_thread(rt_thread, ThreadId::kRtLoop, [&] {
    prefault_stack(cfg.thread(ThreadId::kRtLoop).stack_bytes);
    CycleClock cc(stepped ? CycleClock::Mode::kStepped : CycleClock::Mode::kLive, ts.period_ns,
                  stepped ? opt.speed : 0.0);
    if (opt.on_rt_start) opt.on_rt_start();
    timespec cpu0{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &cpu0);
    if (stepped)
      cc.start();
    else
      cc.start(live_clock.origin_ns());
    for (;;) {
      if (opt.stop != nullptr && opt.stop->load(std::memory_order_relaxed)) break;
      if (stepped && opt.lockstep) {
        while (twin->windows_outstanding() > 0 &&
               !(opt.stop != nullptr && opt.stop->load(std::memory_order_relaxed)))
          std::this_thread::sleep_for(std::chrono::microseconds(200));
      }
      const CycleClock::Tick t = cc.wait();
      if (end_ns > 0 && t.now.count() >= end_ns) break;
      manual_clock.set(t.now);
      twin->cycle(t.now);
      if (opt.on_cycle) opt.on_cycle(*twin, t.now);
      const double cycle_us = cc.cycle_time_us();
      twin->record_timing(t.latency_us, cycle_us, t.overran, t.skipped);
      if (opt.timing != nullptr) opt.timing->add(t.latency_us, cycle_us, t.overran);
      last_now = t.now;
      last_now_ns.store(t.now.count(), std::memory_order_relaxed);
    }
    twin->publish(last_now);
    timespec cpu1{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &cpu1);
    summary.rt_cpu_s = static_cast<double>(cpu1.tv_sec - cpu0.tv_sec) +
                       1e-9 * static_cast<double>(cpu1.tv_nsec - cpu0.tv_nsec);
    if (opt.on_rt_stop) opt.on_rt_stop();
  });
  summary.rt_thread_warning = rt_thread.report().warning;
  rt_thread.join();

  // ---- stop ----
  if (calibration) calibration->request_stop();
  calibration_thread.join();
  workers_stop = true;
  persistence_thread.join();
  service_thread.join();
  trends_stop = true;  // after the RT thread's last publish
  trends_thread.join();
  if (state_ok) {
    std::string err;
    if (!store.save(twin->accumulator().state(), last_now.count(), &err))
      log.line("drivetwin run: ERR: final checkpoint: " + err);
  }
  if (outputs) (void)outputs->deactivate();
  if (results) (void)results->deactivate();
  if (keyphasor) (void)keyphasor->deactivate();
  if (cms) (void)cms->deactivate();
  (void)scada->deactivate();

  summary.last = twin->last_snapshot();
  summary.elapsed_s = twin->accumulator().elapsed_s();
  for (std::size_t c = 0; c < channels.channel_count(); ++c)
    summary.damage.push_back(twin->accumulator().damage(c));
  summary.loop_time_s = std::chrono::duration<double>(last_now).count();
  summary.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  summary.calibration_generation = twin->last_snapshot().calibration_generation;
  // The models the RT thread held (the mailbox frees what it still holds itself).
  delete twin->rom_in_use();
  delete twin->rom_settling();
  delete twin->rom_not_returned();
  return summary;
}

}  // namespace app::loop
