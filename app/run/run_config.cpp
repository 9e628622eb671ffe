// The run configuration's parameter table, loader and reference: see run_config.hpp.
#include "run/run_config.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <iomanip>
#include <limits>
#include <map>
#include <set>
#include <sstream>

namespace app::run {
namespace {

// Parameter builders: one line per parameter in the table below.
Param real(std::string key, double def, double lo, double hi, std::string unit,
           std::string description, double* (*to)(RunConfig&)) {
  Param p;
  p.key = std::move(key);
  p.type = ParamType::kReal;
  std::ostringstream d;
  d << std::setprecision(15) << def;
  p.default_text = d.str();
  if (p.default_text.find_first_of(".e") == std::string::npos) p.default_text += ".0";
  p.min = lo;
  p.max = hi;
  p.unit = std::move(unit);
  p.description = std::move(description);
  p.as_real = to;
  return p;
}

Param integer(std::string key, std::int64_t def, double lo, double hi, std::string unit,
              std::string description, std::int64_t* (*to)(RunConfig&)) {
  Param p;
  p.key = std::move(key);
  p.type = ParamType::kInt;
  p.default_text = std::to_string(def);
  p.min = lo;
  p.max = hi;
  p.unit = std::move(unit);
  p.description = std::move(description);
  p.as_int = to;
  return p;
}

Param boolean(std::string key, bool def, std::string description, bool* (*to)(RunConfig&)) {
  Param p;
  p.key = std::move(key);
  p.type = ParamType::kBool;
  p.default_text = def ? "true" : "false";
  p.description = std::move(description);
  p.as_bool = to;
  return p;
}

Param text(std::string key, std::string def, std::string description,
           std::string* (*to)(RunConfig&)) {
  Param p;
  p.key = std::move(key);
  p.type = ParamType::kString;
  p.default_text = "\"" + def + "\"";
  p.description = std::move(description);
  p.as_string = to;
  return p;
}

template <std::size_t N>
Param choice(std::string key, std::string_view def, const std::array<std::string_view, N>& choices,
             std::string description, int* (*to)(RunConfig&)) {
  Param p;
  p.key = std::move(key);
  p.type = ParamType::kChoice;
  p.default_text = "\"" + std::string(def) + "\"";
  p.choices.assign(choices.begin(), choices.end());
  p.description = std::move(description);
  p.as_choice = to;
  return p;
}

constexpr std::array<std::string_view, 5> kPolicyChoices{"other", "batch", "idle", "fifo", "rr"};
constexpr std::array<hal::SchedPolicy, 5> kPolicies{
    hal::SchedPolicy::kOther, hal::SchedPolicy::kBatch, hal::SchedPolicy::kIdle,
    hal::SchedPolicy::kFifo, hal::SchedPolicy::kRoundRobin};
enum ThreadField { kPolicy, kPriority, kCpu, kStack };

int policy_index(hal::SchedPolicy p) {
  for (std::size_t i = 0; i < kPolicies.size(); ++i)
    if (kPolicies[i] == p) return static_cast<int>(i);
  return 0;
}

std::vector<Param> build_table() {
  std::vector<Param> t;
  // [twin]
  t.push_back(text("twin.drivetrain", "paper-2mw",
                   "Drivetrain: a built-in name (paper-2mw, kelmarsh-mm92) or a description file "
                   "(app/config/README.md), relative to this file",
                   [](RunConfig& c) { return &c.drivetrain; }));
  t.push_back(text("twin.bus", "bus.toml",
                   "Bus configuration file (format drivetwin-bus/1, hal/README.md), relative to "
                   "this file; `drivetwin bus probe --config` commissions the same file",
                   [](RunConfig& c) { return &c.bus; }));
  t.push_back(text("twin.state_dir", "state",
                   "Folder of the persisted state (damage accumulators, rate history, "
                   "calibration), relative to this file; created if missing",
                   [](RunConfig& c) { return &c.state_dir; }));
  // [loop]
  t.push_back(integer("loop.period_us", 1000, 100, 100000, "µs",
                      "Cycle period T of the real-time loop",
                      [](RunConfig& c) { return &c.period_us; }));
  t.push_back(integer("loop.rom_steps_per_cycle", 8, 1, 256, "",
                      "ROM steps per cycle; the ROM's fixed step is T / steps (its sample rate "
                      "should be ≥ 6 × the highest mesh harmonic it must resolve, rom.hpp)",
                      [](RunConfig& c) { return &c.rom_steps_per_cycle; }));
  t.push_back(real("loop.rom_cutoff_hz", 2200.0, 50.0, 2500.0, "Hz",
                   "ROM mode cut-off: every full-model mode up to here is kept (capacity "
                   "kRomDofs; 2200 Hz fills it for paper-2mw)",
                   [](RunConfig& c) { return &c.rom_cutoff_hz; }));
  t.push_back(integer("loop.publish_divisor", 100, 1, 100000, "",
                      "A results snapshot (register image, trends, log) every N cycles",
                      [](RunConfig& c) { return &c.publish_divisor; }));
  t.push_back(real("loop.overrun_warn_interval_s", 10.0, 0.0, 3600.0, "s",
                   "At most one overrun warning in the log per interval (all are counted)",
                   [](RunConfig& c) { return &c.overrun_warn_interval_s; }));
  // [inputs]
  t.push_back(choice("inputs.torque_source", "auto", kTorqueSourceChoices,
                     "ROM input torque: auto = measured torque, else power and rotor speed, "
                     "else wind speed through the wind load model; or force one",
                     [](RunConfig& c) { return &c.torque_source; }));
  t.push_back(real("inputs.scada_hold_s", 60.0, 0.0, 3600.0, "s",
                   "SCADA stale or missing: the last valid values are held this long, then the "
                   "controller's steady-state torque at the last valid wind is used (flagged)",
                   [](RunConfig& c) { return &c.scada_hold_s; }));
  t.push_back(real("vibration.cms_sample_rate_hz", 25600.0, 1000.0, 200000.0, "Hz",
                   "Sample rate of the CMS accelerometer channels (a replayed recording bundle "
                   "brings its own)",
                   [](RunConfig& c) { return &c.cms_sample_rate_hz; }));
  t.push_back(integer("vibration.point1_channel", 0, 0, 15, "",
                      "CMS channel id of measurement point 1 (high-speed shaft bearing seat)",
                      [](RunConfig& c) { return &c.point1_channel; }));
  t.push_back(integer("vibration.point2_channel", 1, 0, 15, "",
                      "CMS channel id of measurement point 2 (intermediate shaft bearing seat)",
                      [](RunConfig& c) { return &c.point2_channel; }));
  t.push_back(real("vibration.accel_hf_bc_mps2", 7.5, 0.01, 1000.0, "m/s²",
                   "Zone B/C boundary, gearbox acceleration rms 10 Hz–2 kHz (ISO 10816-21 "
                   "Annex A)",
                   [](RunConfig& c) { return &c.accel_hf_bc_mps2; }));
  t.push_back(real("vibration.accel_hf_cd_mps2", 12.0, 0.01, 1000.0, "m/s²",
                   "Zone C/D boundary, gearbox acceleration rms 10 Hz–2 kHz",
                   [](RunConfig& c) { return &c.accel_hf_cd_mps2; }));
  t.push_back(real("vibration.velocity_bc_mmps", 3.5, 0.01, 1000.0, "mm/s",
                   "Zone B/C boundary, gearbox velocity rms 10 Hz–1 kHz",
                   [](RunConfig& c) { return &c.velocity_bc_mmps; }));
  t.push_back(real("vibration.velocity_cd_mmps", 5.6, 0.01, 1000.0, "mm/s",
                   "Zone C/D boundary, gearbox velocity rms 10 Hz–1 kHz",
                   [](RunConfig& c) { return &c.velocity_cd_mmps; }));
  t.push_back(real("vibration.accel_lf_bc_mps2", 0.3, 0.001, 100.0, "m/s²",
                   "Zone B/C boundary, gearbox acceleration rms 0.1–10 Hz",
                   [](RunConfig& c) { return &c.accel_lf_bc_mps2; }));
  t.push_back(real("vibration.accel_lf_cd_mps2", 0.5, 0.001, 100.0, "m/s²",
                   "Zone C/D boundary, gearbox acceleration rms 0.1–10 Hz",
                   [](RunConfig& c) { return &c.accel_lf_cd_mps2; }));
  t.push_back(real("vibration.hf_interval_s", 60.0, 1.0, 3600.0, "s",
                   "Evaluation period of the 10 Hz–2 kHz and 10 Hz–1 kHz bands (interval rms)",
                   [](RunConfig& c) { return &c.hf_interval_s; }));
  t.push_back(real("vibration.lf_interval_s", 600.0, 10.0, 7200.0, "s",
                   "Evaluation period of the 0.1–10 Hz band (interval rms)",
                   [](RunConfig& c) { return &c.lf_interval_s; }));
  t.push_back(choice("vibration.alarm_zone", "D", kAlarmZoneChoices,
                     "The zone from which the alarm output is raised (C: already at ALERT)",
                     [](RunConfig& c) { return &c.alarm_zone; }));
  // [calibration]
  t.push_back(boolean("calibration.enabled", true,
                      "Compare the model with the CMS and recalibrate on the calibration thread",
                      [](RunConfig& c) { return &c.calibration_enabled; }));
  t.push_back(choice("calibration.method", "trust-region", kCalibrationMethodChoices,
                     "Optimiser (docs/calibration.md)",
                     [](RunConfig& c) { return &c.calibration_method; }));
  t.push_back(choice("calibration.space", "standard", kCalibrationSpaceChoices,
                     "Variables calibrated: 'standard' (as drivetwin calibrate: mesh excitation, "
                     "housing modes per point, stiffness per bearing, damping bands, with the "
                     "paper's; those the window identifies are fitted, the others stay at the "
                     "description's values; docs/calibration.md) or 'paper' (the paper's 8: "
                     "Rayleigh eta and zeta, a mesh-stiffness scale per stage, a bearing-stiffness "
                     "scale per parallel shaft; the space the MOGOA methods were compared on)",
                     [](RunConfig& c) { return &c.calibration_space; }));
  t.push_back(real("calibration.window_s", 6.0, 0.25, 60.0, "s",
                   "Length of a gap-free CMS window compared with the model (the order "
                   "tracking needs 64 high-speed shaft revolutions: 4.5 s at 858 rpm)",
                   [](RunConfig& c) { return &c.window_s; }));
  t.push_back(real("calibration.check_interval_s", 600.0, 1.0, 86400.0, "s",
                   "Time between two comparisons of the model with a CMS window",
                   [](RunConfig& c) { return &c.check_interval_s; }));
  t.push_back(real("calibration.steady_speed_tolerance", 0.05, 0.0, 1.0, "",
                   "A window counts only if the rotor speed stays within this fraction of its "
                   "mean (the model is compared at one operating point)",
                   [](RunConfig& c) { return &c.steady_speed_tolerance; }));
  t.push_back(real("calibration.steady_torque_tolerance", 0.10, 0.0, 1.0, "",
                   "… and the input torque within this fraction of its mean",
                   [](RunConfig& c) { return &c.steady_torque_tolerance; }));
  t.push_back(integer("calibration.max_evaluations", 30, 9, 10000, "",
                      "Model evaluations of each trust-region fit round (as drivetwin "
                      "calibrate; the identification probes, one per variable, come on top; at "
                      "most 8 rounds)",
                      [](RunConfig& c) { return &c.max_evaluations; }));
  t.push_back(boolean("calibration.diagnosis", true,
                      "When a calibration cannot reach the thresholds, run the missing-physics "
                      "diagnosis (docs/diagnosis.md) on that window, on the calibration thread",
                      [](RunConfig& c) { return &c.diagnosis_enabled; }));
  t.push_back(real("calibration.diagnosis_interval_s", 86400.0, 0.0, 365.0 * 86400.0, "s",
                   "Loop time between two diagnoses (a diagnosis costs minutes of low-priority "
                   "CPU)",
                   [](RunConfig& c) { return &c.diagnosis_interval_s; }));
  // [fatigue]
  t.push_back(integer("fatigue.bins", 200, 16, 256, "",
                      "Stress bins per damage channel (ISO 6336-6 load-duration histogram)",
                      [](RunConfig& c) { return &c.bins; }));
  t.push_back(real("fatigue.rul_interval_s", 86400.0, 60.0, 31.0 * 86400.0, "s",
                   "Interval of the damage-rate history the RUL is estimated from",
                   [](RunConfig& c) { return &c.rul_interval_s; }));
  t.push_back(integer("fatigue.rul_short_window", 30, 1, 4096, "",
                      "Intervals of the short-term damage rate",
                      [](RunConfig& c) { return &c.rul_short_window; }));
  // [persistence]
  t.push_back(real("persistence.checkpoint_interval_s", 60.0, 1.0, 86400.0, "s",
                   "The state is saved crash-safely this often (and on SIGTERM)",
                   [](RunConfig& c) { return &c.checkpoint_interval_s; }));
  // [log]
  t.push_back(real("log.interval_s", 10.0, 0.0, 86400.0, "s",
                   "At most one log line per event code per interval; repeats are counted and "
                   "reported with the next line",
                   [](RunConfig& c) { return &c.log_interval_s; }));
  // [threads.<key>]: generated from the constexpr thread table.
  for (std::size_t i = 0; i < kThreadCount; ++i) {
    const hal::ThreadAttributes& d = kDefaultThreads[i];
    const std::string prefix = "threads." + std::string(kThreadKeys[i]) + ".";
    const std::string who = std::string("thread ") + d.name;
    Param p =
        choice(prefix + "policy", kPolicyChoices[static_cast<std::size_t>(policy_index(d.policy))],
               kPolicyChoices,
               who +
                   ": scheduling policy (fifo/rr: real-time; idle: only "
                   "idle CPU time)",
               nullptr);
    p.thread = static_cast<int>(i);
    p.thread_field = kPolicy;
    t.push_back(p);
    p = integer(prefix + "priority", d.priority, -20, 99, "",
                who + ": fifo/rr priority 1..99, or the nice value −20..19 for other/batch",
                nullptr);
    p.thread = static_cast<int>(i);
    p.thread_field = kPriority;
    t.push_back(p);
    p = integer(prefix + "cpu", d.cpu, -1, 1023, "", who + ": CPU to pin to (−1: any)", nullptr);
    p.thread = static_cast<int>(i);
    p.thread_field = kCpu;
    t.push_back(p);
    p = integer(prefix + "stack_kib", static_cast<std::int64_t>(d.stack_bytes / kKiB), 16, 65536,
                "KiB", who + ": stack size", nullptr);
    p.thread = static_cast<int>(i);
    p.thread_field = kStack;
    t.push_back(p);
  }
  return t;
}

[[noreturn]] void fail(const std::filesystem::path& file, const toml::node* node,
                       const std::string& key, const std::string& what) {
  std::ostringstream m;
  m << file.string();
  if (node != nullptr && node->source().begin.line > 0) m << ":" << node->source().begin.line;
  if (!key.empty()) m << ": " << key;
  m << ": " << what;
  throw RunConfigError(m.str());
}

std::string range_text(const Param& p) {
  std::ostringstream m;
  m << "[" << p.min << ", " << p.max << "]";
  return m.str();
}

std::string choices_text(const Param& p) {
  std::string s;
  for (std::string_view c : p.choices) s += (s.empty() ? "" : ", ") + std::string(c);
  return s;
}

void set_thread_field(RunConfig& c, const Param& p, std::int64_t value) {
  hal::ThreadAttributes& a = c.threads[static_cast<std::size_t>(p.thread)];
  switch (p.thread_field) {
    case kPolicy:
      a.policy = kPolicies[static_cast<std::size_t>(value)];
      break;
    case kPriority:
      a.priority = static_cast<int>(value);
      break;
    case kCpu:
      a.cpu = static_cast<int>(value);
      break;
    case kStack:
      a.stack_bytes = static_cast<std::size_t>(value) * kKiB;
      break;
    default:
      break;
  }
}

// Assigns one TOML value to its parameter after checking type and range.
void assign(RunConfig& c, const Param& p, const toml::node& n, const std::filesystem::path& file) {
  switch (p.type) {
    case ParamType::kBool:
      if (!n.is_boolean()) fail(file, &n, p.key, "expected true or false");
      *p.as_bool(c) = *n.value<bool>();
      return;
    case ParamType::kString:
      if (!n.is_string()) fail(file, &n, p.key, "expected a string");
      *p.as_string(c) = *n.value<std::string>();
      if (p.as_string(c)->empty()) fail(file, &n, p.key, "must not be empty");
      return;
    case ParamType::kChoice: {
      if (!n.is_string()) fail(file, &n, p.key, "expected one of: " + choices_text(p));
      const std::string v = *n.value<std::string>();
      const auto it = std::find(p.choices.begin(), p.choices.end(), v);
      if (it == p.choices.end())
        fail(file, &n, p.key, "is \"" + v + "\"; expected one of: " + choices_text(p));
      const int index = static_cast<int>(it - p.choices.begin());
      if (p.thread >= 0) {
        set_thread_field(c, p, index);
      } else {
        *p.as_choice(c) = index;
      }
      return;
    }
    case ParamType::kInt: {
      if (!n.is_integer()) fail(file, &n, p.key, "expected an integer in " + range_text(p));
      const std::int64_t v = *n.value<std::int64_t>();
      if (static_cast<double>(v) < p.min || static_cast<double>(v) > p.max) {
        fail(file, &n, p.key,
             "is " + std::to_string(v) + "; expected an integer in " + range_text(p));
      }
      if (p.thread >= 0) {
        set_thread_field(c, p, v);
      } else {
        *p.as_int(c) = v;
      }
      return;
    }
    case ParamType::kReal: {
      if (!n.is_number()) fail(file, &n, p.key, "expected a number in " + range_text(p));
      const double v = *n.value<double>();
      if (!std::isfinite(v) || v < p.min || v > p.max) {
        std::ostringstream m;
        m << "is " << v << "; expected a number in " << range_text(p);
        if (!p.unit.empty()) m << " " << p.unit;
        fail(file, &n, p.key, m.str());
      }
      *p.as_real(c) = v;
      return;
    }
  }
}

// Applies a parameter's default (parsed from its default text, so that the table is the
// only place a default is written).
void apply_default(RunConfig& c, const Param& p) {
  const std::string doc = "v = " + p.default_text;
  const toml::table t = toml::parse(doc);
  assign(c, p, *t.get("v"), "<default of " + p.key + ">");
}

std::string resolve(const std::filesystem::path& base, const std::string& p) {
  if (p.rfind("builtin:", 0) == 0) return p;
  const std::filesystem::path path(p);
  return path.is_absolute() ? path.string() : (base / path).lexically_normal().string();
}

// Cross-parameter rules.
void check_relations(const RunConfig& c, const toml::table& root,
                     const std::filesystem::path& file) {
  const auto node = [&](const char* key) { return root.at_path(key).node(); };
  if (c.accel_hf_cd_mps2 <= c.accel_hf_bc_mps2)
    fail(file, node("vibration.accel_hf_cd_mps2"), "vibration.accel_hf_cd_mps2",
         "must be above vibration.accel_hf_bc_mps2 (zone C lies between them)");
  if (c.velocity_cd_mmps <= c.velocity_bc_mmps)
    fail(file, node("vibration.velocity_cd_mmps"), "vibration.velocity_cd_mmps",
         "must be above vibration.velocity_bc_mmps");
  if (c.accel_lf_cd_mps2 <= c.accel_lf_bc_mps2)
    fail(file, node("vibration.accel_lf_cd_mps2"), "vibration.accel_lf_cd_mps2",
         "must be above vibration.accel_lf_bc_mps2");
  if (c.point1_channel == c.point2_channel)
    fail(file, node("vibration.point2_channel"), "vibration.point2_channel",
         "must differ from vibration.point1_channel");
  if (c.window_s * 1e6 < 2.0 * static_cast<double>(c.period_us))
    fail(file, node("calibration.window_s"), "calibration.window_s",
         "must span at least two loop periods");
  for (std::size_t i = 0; i < kThreadCount; ++i) {
    const std::string problem = hal::validate(c.threads[i]);
    if (!problem.empty()) {
      const std::string key = "threads." + std::string(kThreadKeys[i]);
      fail(file, root.at_path(key).node(), key, problem);
    }
  }
}

}  // namespace

const char* to_string(ParamType t) {
  switch (t) {
    case ParamType::kBool:
      return "bool";
    case ParamType::kInt:
      return "integer";
    case ParamType::kReal:
      return "real";
    case ParamType::kString:
      return "string";
    case ParamType::kChoice:
      return "choice";
  }
  return "?";
}

const std::vector<Param>& run_parameters() {
  static const std::vector<Param> table = build_table();
  return table;
}

RunConfig default_run_config() {
  RunConfig c;
  c.threads = kDefaultThreads;
  for (const Param& p : run_parameters()) apply_default(c, p);
  return c;
}

RunConfig parse_run_config(std::string_view text_in, const std::filesystem::path& name) {
  toml::table root;
  try {
    root = toml::parse(text_in, name.string());
  } catch (const toml::parse_error& e) {
    std::ostringstream m;
    m << name.string() << ":" << e.source().begin.line << ": " << e.description();
    throw RunConfigError(m.str());
  }
  RunConfig c = default_run_config();
  c.file = name;
  // Format first: a file of another kind is named as such, not as a list of unknown keys.
  const toml::node* format = root.get("format");
  if (format == nullptr)
    fail(name, nullptr, "format", std::string("missing; expected \"") + kRunFormat + "\"");
  if (!format->is_string() || *format->value<std::string>() != kRunFormat)
    fail(name, format, "format", std::string("expected \"") + kRunFormat + "\"");

  std::map<std::string, const Param*> by_key;
  std::set<std::string> tables{""};
  for (const Param& p : run_parameters()) {
    by_key[p.key] = &p;
    for (std::size_t dot = p.key.find('.'); dot != std::string::npos;
         dot = p.key.find('.', dot + 1))
      tables.insert(p.key.substr(0, dot));
  }
  // Walk every node: tables must be known tables, leaves known parameters.
  std::function<void(const toml::table&, const std::string&)> walk =
      [&](const toml::table& t, const std::string& prefix) {
        for (const auto& [k, v] : t) {
          const std::string key =
              prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
          if (key == "format") continue;
          if (v.is_table()) {
            if (tables.count(key) == 0) fail(name, &v, key, "unknown table");
            walk(*v.as_table(), key);
            continue;
          }
          const auto it = by_key.find(key);
          if (it == by_key.end()) {
            // The keys that would have been right at this level.
            std::string near;
            for (const auto& [known, param] : by_key) {
              if (prefix.empty() || known.rfind(prefix + ".", 0) != 0) continue;
              const std::string rest = known.substr(prefix.size() + 1);
              if (rest.find('.') == std::string::npos) near += (near.empty() ? "" : ", ") + rest;
            }
            fail(name, &v, key,
                 "unknown key" + (near.empty() ? std::string() : "; expected one of: " + near));
          }
          assign(c, *it->second, v, name);
        }
      };
  walk(root, "");
  const std::filesystem::path base = name.parent_path();
  c.drivetrain =
      c.drivetrain.find('/') != std::string::npos || c.drivetrain.find(".toml") != std::string::npos
          ? resolve(base, c.drivetrain)
          : c.drivetrain;
  c.bus = resolve(base, c.bus);
  c.state_dir = resolve(base, c.state_dir);
  check_relations(c, root, name);
  return c;
}

RunConfig load_run_config(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw RunConfigError(file.string() + ": cannot open for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_run_config(ss.str(), file);
}

std::string run_config_reference() {
  std::ostringstream o;
  o << "| key | type | default | range / choices | unit | description |\n"
    << "|---|---|---|---|---|---|\n";
  for (const Param& p : run_parameters()) {
    std::string range;
    if (p.type == ParamType::kInt || p.type == ParamType::kReal) {
      std::ostringstream r;
      r << p.min << " … " << p.max;
      range = r.str();
    } else if (p.type == ParamType::kChoice) {
      range = choices_text(p);
    }
    o << "| `" << p.key << "` | " << to_string(p.type) << " | `" << p.default_text << "` | "
      << range << " | " << p.unit << " | " << p.description << " |\n";
  }
  return o.str();
}

std::string describe(const RunConfig& c_in) {
  RunConfig c = c_in;
  std::ostringstream o;
  o << std::setprecision(10);
  for (const Param& p : run_parameters()) {
    o << p.key << " = ";
    if (p.thread >= 0) {
      const hal::ThreadAttributes& a = c.threads[static_cast<std::size_t>(p.thread)];
      switch (p.thread_field) {
        case kPolicy:
          o << kPolicyChoices[static_cast<std::size_t>(policy_index(a.policy))];
          break;
        case kPriority:
          o << a.priority;
          break;
        case kCpu:
          o << a.cpu;
          break;
        case kStack:
          o << a.stack_bytes / kKiB;
          break;
        default:
          break;
      }
    } else {
      switch (p.type) {
        case ParamType::kBool:
          o << (*p.as_bool(c) ? "true" : "false");
          break;
        case ParamType::kInt:
          o << *p.as_int(c);
          break;
        case ParamType::kReal:
          o << *p.as_real(c);
          break;
        case ParamType::kString:
          o << "\"" << *p.as_string(c) << "\"";
          break;
        case ParamType::kChoice:
          o << p.choices[static_cast<std::size_t>(*p.as_choice(c))];
          break;
      }
    }
    if (!p.unit.empty()) o << " " << p.unit;
    o << "\n";
  }
  return o.str();
}

}  // namespace app::run
