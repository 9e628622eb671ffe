// Bus configuration file parser: see bus_config.hpp and hal/README.md.
#include "bus/bus_config.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include "results/register_map.hpp"

namespace app::bus {
namespace {

class Reader {
 public:
  explicit Reader(std::filesystem::path file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const toml::node* node, const std::string& key,
                         const std::string& what) const {
    std::ostringstream m;
    m << file_.string();
    if (node != nullptr && node->source().begin.line > 0) m << ":" << node->source().begin.line;
    if (!key.empty()) m << ": " << key;
    m << ": " << what;
    throw BusConfigError(m.str());
  }

  /// Rejects keys not in `allowed` (typos must not pass silently).
  void only(const toml::table& t, const std::string& prefix,
            std::initializer_list<const char*> allowed) const {
    for (const auto& [k, v] : t) {
      const std::string key(k.str());
      if (std::none_of(allowed.begin(), allowed.end(), [&](const char* a) { return key == a; })) {
        std::string list;
        for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
        fail(&v, prefix + key, "unknown key; expected one of: " + list);
      }
    }
  }

  const toml::table* table(const toml::table& t, const char* k, const std::string& prefix) const {
    const toml::node* n = t.get(k);
    if (n == nullptr) return nullptr;
    if (!n->is_table()) fail(n, prefix + k, "expected a table");
    return n->as_table();
  }

  std::optional<std::string> str(const toml::table& t, const char* k,
                                 const std::string& prefix) const {
    const toml::node* n = t.get(k);
    if (n == nullptr) return std::nullopt;
    if (!n->is_string()) fail(n, prefix + k, "expected a string");
    return n->value<std::string>();
  }

  std::optional<bool> boolean(const toml::table& t, const char* k,
                              const std::string& prefix) const {
    const toml::node* n = t.get(k);
    if (n == nullptr) return std::nullopt;
    if (!n->is_boolean()) fail(n, prefix + k, "expected true or false");
    return n->value<bool>();
  }

  std::optional<double> number(const toml::table& t, const char* k, const std::string& prefix,
                               double lo, double hi) const {
    const toml::node* n = t.get(k);
    if (n == nullptr) return std::nullopt;
    if (!n->is_number()) fail(n, prefix + k, "expected a number");
    const double v = *n->value<double>();
    if (!std::isfinite(v) || v < lo || v > hi) {
      std::ostringstream m;
      m << "is " << v << "; expected a number in [" << lo << ", " << hi << "]";
      fail(n, prefix + k, m.str());
    }
    return v;
  }

  std::optional<std::int64_t> integer(const toml::table& t, const char* k,
                                      const std::string& prefix, std::int64_t lo,
                                      std::int64_t hi) const {
    const toml::node* n = t.get(k);
    if (n == nullptr) return std::nullopt;
    if (!n->is_integer()) fail(n, prefix + k, "expected an integer");
    const std::int64_t v = *n->value<std::int64_t>();
    if (v < lo || v > hi) {
      fail(n, prefix + k,
           "is " + std::to_string(v) + "; expected an integer in [" + std::to_string(lo) + ", " +
               std::to_string(hi) + "]");
    }
    return v;
  }

  std::chrono::milliseconds ms(const toml::table& t, const char* k, const std::string& prefix,
                               std::chrono::milliseconds dflt, std::int64_t lo = 1,
                               std::int64_t hi = 3'600'000) const {
    const auto v = integer(t, k, prefix, lo, hi);
    return v ? std::chrono::milliseconds(*v) : dflt;
  }

  hal::SimFault fault(const toml::table& t, const std::string& prefix) const {
    hal::SimFault f = hal::SimFault::kNone;
    if (const auto s = str(t, "fault", prefix)) {
      if (!hal::parse_sim_fault(s->c_str(), f)) {
        fail(t.get("fault"), prefix + "fault",
             "'" + *s +
                 "'; expected none, silent, stuck, noisy, garbage, gaps, bus_off, non_finite or "
                 "out_of_range");
      }
    }
    return f;
  }

  Backend backend(const toml::table& t, const std::string& prefix, const char* linux_name,
                  std::initializer_list<const char*> others) const {
    const auto s = str(t, "backend", prefix);
    if (!s) {
      fail(
          &t, prefix + "backend",
          std::string("missing; expected \"") + linux_name + "\", \"replay\", \"sim\" or \"none\"");
    }
    if (*s == linux_name) return Backend::kLinux;
    if (*s == "none") return Backend::kNone;
    for (const char* o : others) {
      if (*s == o && std::string(o) == "replay") return Backend::kReplay;
      if (*s == o && (std::string(o) == "sim" || std::string(o) == "memory")) return Backend::kSim;
    }
    std::string list = std::string("\"") + linux_name + "\"";
    for (const char* o : others) list += std::string(", \"") + o + "\"";
    fail(t.get("backend"), prefix + "backend", "'" + *s + "'; expected " + list + " or \"none\"");
  }

  const std::filesystem::path& file() const { return file_; }

 private:
  std::filesystem::path file_;
};

void read_scada(const Reader& r, const toml::table& t, BusConfig& c) {
  const std::string p = "scada.";
  r.only(t, p,
         {"backend",
          "transport",
          "host",
          "port",
          "device",
          "baud",
          "parity",
          "data_bits",
          "stop_bits",
          "unit_id",
          "poll_period_ms",
          "response_timeout_ms",
          "min_backoff_ms",
          "max_backoff_ms",
          "stale_after_ms",
          "max_hole",
          "invalid_mask",
          "register",
          "csv",
          "columns",
          "fault"});
  c.scada = r.backend(t, p, "modbus", {"replay", "sim"});
  c.scada_fault = r.fault(t, p);
  if (const auto s = r.str(t, "csv", p)) c.scada_csv = (r.file().parent_path() / *s).string();
  if (const auto s = r.str(t, "columns", p)) c.scada_columns = *s;
  hal::ModbusClientConfig& m = c.modbus_client;
  if (const auto s = r.str(t, "transport", p)) {
    if (*s == "tcp") {
      m.transport = hal::ModbusClientConfig::Transport::kTcp;
    } else if (*s == "rtu") {
      m.transport = hal::ModbusClientConfig::Transport::kRtu;
    } else {
      r.fail(t.get("transport"), p + "transport", "'" + *s + "'; expected \"tcp\" or \"rtu\"");
    }
  }
  if (const auto s = r.str(t, "host", p)) m.host = *s;
  if (const auto v = r.integer(t, "port", p, 1, 65535)) m.port = static_cast<std::uint16_t>(*v);
  if (const auto s = r.str(t, "device", p)) m.device = *s;
  if (const auto v = r.integer(t, "baud", p, 1200, 921600)) m.baud = static_cast<int>(*v);
  if (const auto s = r.str(t, "parity", p)) {
    if (*s == "none") {
      m.parity = 'N';
    } else if (*s == "even") {
      m.parity = 'E';
    } else if (*s == "odd") {
      m.parity = 'O';
    } else {
      r.fail(t.get("parity"), p + "parity", "'" + *s + "'; expected \"none\", \"even\" or \"odd\"");
    }
  }
  if (const auto v = r.integer(t, "data_bits", p, 7, 8)) m.data_bits = static_cast<int>(*v);
  if (const auto v = r.integer(t, "stop_bits", p, 1, 2)) m.stop_bits = static_cast<int>(*v);
  if (const auto v = r.integer(t, "unit_id", p, 0, 247)) m.unit_id = static_cast<int>(*v);
  m.poll_period = r.ms(t, "poll_period_ms", p, m.poll_period);
  m.response_timeout = r.ms(t, "response_timeout_ms", p, m.response_timeout);
  m.min_backoff = r.ms(t, "min_backoff_ms", p, m.min_backoff);
  m.max_backoff = r.ms(t, "max_backoff_ms", p, m.max_backoff);
  m.stale_after = r.ms(t, "stale_after_ms", p, m.stale_after);
  if (m.max_backoff < m.min_backoff)
    r.fail(t.get("max_backoff_ms"), p + "max_backoff_ms", "must be >= min_backoff_ms");
  if (const auto v = r.integer(t, "max_hole", p, 0, 100))
    m.max_hole = static_cast<std::uint16_t>(*v);

  auto read_function = [&](const toml::table& e, const std::string& prefix,
                           hal::RegisterFunction& f) {
    if (const auto s = r.str(e, "function", prefix)) {
      if (!hal::parse_register_function(*s, f)) {
        r.fail(e.get("function"), prefix + "function",
               "'" + *s + "'; expected \"holding\" or \"input\"");
      }
    }
  };
  if (const toml::table* mask = r.table(t, "invalid_mask", p)) {
    const std::string mp = p + "invalid_mask.";
    r.only(*mask, mp, {"address", "function"});
    hal::RegisterSpec s;
    const auto a = r.integer(*mask, "address", mp, 0, 65535);
    if (!a) r.fail(mask, mp + "address", "missing; expected the register address (0-based)");
    s.address = static_cast<std::uint16_t>(*a);
    read_function(*mask, mp, s.function);
    m.map.invalid_mask = s;
  }
  if (const toml::node* regs = t.get("register")) {
    const toml::array* arr = regs->as_array();
    if (arr == nullptr || !arr->is_array_of_tables())
      r.fail(regs, p + "register", "expected [[scada.register]] tables");
    if (arr->size() > m.map.entries.size()) {
      r.fail(regs, p + "register",
             "more than " + std::to_string(m.map.entries.size()) + " registers (one per quantity)");
    }
    for (std::size_t i = 0; i < arr->size(); ++i) {
      const toml::table& e = *arr->get(i)->as_table();
      const std::string rp = p + "register[" + std::to_string(i) + "].";
      r.only(e, rp,
             {"quantity", "address", "function", "type", "word_order", "scale", "offset", "unit"});
      hal::ScadaRegister& reg = m.map.entries[m.map.count];
      const auto q = r.str(e, "quantity", rp);
      if (!q || !hal::scada_quantity_from_key(*q, reg.quantity)) {
        std::string list;
        for (const auto& qi : hal::kScadaQuantities)
          list += (list.empty() ? "" : ", ") + std::string(qi.key);
        r.fail(e.get("quantity") ? e.get("quantity") : &e, rp + "quantity",
               (q ? "'" + *q + "'" : std::string("missing")) + "; expected one of: " + list);
      }
      const auto a = r.integer(e, "address", rp, 0, 65535);
      if (!a) r.fail(&e, rp + "address", "missing; expected the register address (0-based)");
      reg.spec.address = static_cast<std::uint16_t>(*a);
      read_function(e, rp, reg.spec.function);
      if (const auto s = r.str(e, "type", rp)) {
        if (!hal::parse_register_type(*s, reg.spec.type)) {
          r.fail(e.get("type"), rp + "type",
                 "'" + *s + "'; expected int16, uint16, int32, uint32 or float32");
        }
      }
      if (const auto s = r.str(e, "word_order", rp)) {
        if (!hal::parse_word_order(*s, reg.spec.word_order)) {
          r.fail(e.get("word_order"), rp + "word_order",
                 "'" + *s + "'; expected \"high_first\" (ABCD) or \"low_first\" (CDAB)");
        }
      }
      if (const auto v = r.number(e, "scale", rp, -1e12, 1e12)) reg.spec.scale = *v;
      if (reg.spec.scale == 0.0)
        r.fail(e.get("scale"), rp + "scale", "is 0; expected a non-zero factor");
      if (const auto v = r.number(e, "offset", rp, -1e12, 1e12)) reg.spec.offset = *v;
      const std::string_view want =
          hal::kScadaQuantities[static_cast<std::size_t>(reg.quantity)].unit;
      const auto unit = r.str(e, "unit", rp);
      if (!unit || *unit != want) {
        r.fail(e.get("unit") ? e.get("unit") : &e, rp + "unit",
               (unit ? "'" + *unit + "'" : std::string("missing")) + "; expected '" +
                   std::string(want) + "' for " + *q +
                   " (scale converts the register to this unit)");
      }
      ++m.map.count;
    }
  }
  if (c.scada == Backend::kLinux) {
    if (m.map.count == 0) {
      r.fail(&t, p + "register",
             "no registers; the modbus backend needs at least one [[scada.register]]");
    }
    if (const auto bad = hal::validate_map(m.map)) {
      r.fail(&t,
             p + (*bad < m.map.count ? "register[" + std::to_string(*bad) + "]"
                                     : std::string("invalid_mask")),
             "overlaps another register, repeats a quantity or does not fit the address space");
    }
  }
}

void read_cms(const Reader& r, const toml::table& t, BusConfig& c) {
  const std::string p = "cms.";
  r.only(t, p,
         {"backend", "interface", "fd", "base_id", "classic_format", "stale_after_ms",
          "error_hold_ms", "heartbeat_id", "channel", "fault"});
  c.cms = r.backend(t, p, "socketcan", {"replay", "sim"});
  c.cms_fault = r.fault(t, p);
  hal::SocketCanConfig& s = c.socketcan;
  if (const auto v = r.str(t, "interface", p)) s.interface = *v;
  if (const auto v = r.boolean(t, "fd", p)) s.fd = *v;
  if (const auto v = r.integer(t, "base_id", p, 0, 0x7FF - 15))
    s.base_id = static_cast<std::uint32_t>(*v);
  if (const auto v = r.integer(t, "heartbeat_id", p, 0, 0x7FF))
    s.heartbeat_id = static_cast<std::uint32_t>(*v);
  if (const auto v = r.str(t, "classic_format", p)) {
    if (*v == "int16") {
      s.classic_format = hal::CmsSampleFormat::kInt16;
    } else if (*v == "int24") {
      s.classic_format = hal::CmsSampleFormat::kInt24;
    } else {
      r.fail(t.get("classic_format"), p + "classic_format",
             "'" + *v + "'; expected \"int16\" or \"int24\"");
    }
  }
  s.stale_after = r.ms(t, "stale_after_ms", p, s.stale_after);
  s.error_hold = r.ms(t, "error_hold_ms", p, s.error_hold);
  s.scale.fill(0.0f);
  c.cms_channels.assign(hal::kCmsMaxChannels, {});
  if (const toml::node* chans = t.get("channel")) {
    const toml::array* arr = chans->as_array();
    if (arr == nullptr || !arr->is_array_of_tables())
      r.fail(chans, p + "channel", "expected [[cms.channel]] tables");
    for (std::size_t i = 0; i < arr->size(); ++i) {
      const toml::table& e = *arr->get(i)->as_table();
      const std::string cp = p + "channel[" + std::to_string(i) + "].";
      r.only(e, cp, {"id", "name", "scale", "unit"});
      const auto id =
          r.integer(e, "id", cp, 0, static_cast<std::int64_t>(hal::kCmsMaxChannels) - 1);
      if (!id)
        r.fail(&e, cp + "id", "missing; expected the channel id 0..15 (CAN id = base_id + id)");
      if (s.scale[static_cast<std::size_t>(*id)] != 0.0f)
        r.fail(e.get("id"), cp + "id", "channel configured twice");
      const auto scale = r.number(e, "scale", cp, 1e-12, 1e12);
      if (!scale)
        r.fail(&e, cp + "scale", "missing; expected the value of one LSB in the channel's unit");
      s.scale[static_cast<std::size_t>(*id)] = static_cast<float>(*scale);
      ChannelInfo& info = c.cms_channels[static_cast<std::size_t>(*id)];
      info.name = r.str(e, "name", cp).value_or("ch" + std::to_string(*id));
      const auto unit = r.str(e, "unit", cp);
      if (!unit || unit->empty())
        r.fail(&e, cp + "unit", "missing; expected the unit of the samples, e.g. \"m/s^2\"");
      info.unit = *unit;
    }
  }
  if (c.cms == Backend::kLinux &&
      std::all_of(s.scale.begin(), s.scale.end(), [](float v) { return v == 0.0f; })) {
    r.fail(&t, p + "channel",
           "no channels; the socketcan backend needs at least one [[cms.channel]]");
  }
}

void read_keyphasor(const Reader& r, const toml::table& t, BusConfig& c) {
  const std::string p = "keyphasor.";
  r.only(
      t, p,
      {"backend", "chip", "line", "both_edges", "active_low", "pulses_per_rev", "shaft", "fault"});
  c.keyphasor = r.backend(t, p, "gpio", {"replay", "sim"});
  c.keyphasor_fault = r.fault(t, p);
  if (const auto v = r.str(t, "chip", p)) c.gpio_keyphasor.chip.chip = *v;
  if (const auto v = r.integer(t, "line", p, 0, 1023))
    c.gpio_keyphasor.line = static_cast<unsigned>(*v);
  if (const auto v = r.boolean(t, "both_edges", p)) c.gpio_keyphasor.both_edges = *v;
  if (const auto v = r.boolean(t, "active_low", p)) c.gpio_keyphasor.active_low = *v;
  if (const auto v = r.integer(t, "pulses_per_rev", p, 1, 1000))
    c.pulses_per_rev = static_cast<int>(*v);
  if (const auto v = r.str(t, "shaft", p)) c.keyphasor_shaft = *v;
}

void read_outputs(const Reader& r, const toml::table& t, BusConfig& c) {
  const std::string p = "outputs.";
  r.only(t, p, {"backend", "chip", "watchdog_line", "alarm_line", "alarm_relay_energised_when_ok"});
  c.outputs = r.backend(t, p, "gpio", {"memory"});
  if (const auto v = r.str(t, "chip", p)) c.gpio_outputs.chip.chip = *v;
  if (const auto v = r.integer(t, "watchdog_line", p, 0, 1023))
    c.gpio_outputs.watchdog_line = static_cast<unsigned>(*v);
  if (const auto v = r.integer(t, "alarm_line", p, 0, 1023))
    c.gpio_outputs.alarm_line = static_cast<unsigned>(*v);
  if (const auto v = r.boolean(t, "alarm_relay_energised_when_ok", p))
    c.gpio_outputs.alarm_relay_energised_when_ok = *v;
  if (c.gpio_outputs.watchdog_line == c.gpio_outputs.alarm_line) {
    r.fail(t.get("alarm_line"), p + "alarm_line",
           "same line as watchdog_line; expected two different lines");
  }
}

void read_results(const Reader& r, const toml::table& t, BusConfig& c) {
  const std::string p = "results.";
  r.only(t, p,
         {"backend", "bind", "port", "unit_id", "word_order", "max_connections", "allow",
          "writable", "idle_timeout_ms"});
  c.results = r.backend(t, p, "modbus", {});
  hal::ModbusServerConfig& s = c.modbus_server;
  // The command block is the register map's; the register count is set by whoever
  // builds the map (it depends on the drivetrain's damage channels).
  s.command_start = app::results::RegisterMap::kCommandStart;
  s.command_count = app::results::RegisterMap::kCommandCount;
  if (const auto v = r.str(t, "bind", p)) s.bind_address = *v;
  if (const auto v = r.integer(t, "port", p, 0, 65535)) s.port = static_cast<std::uint16_t>(*v);
  if (const auto v = r.integer(t, "unit_id", p, 1, 247)) s.unit_id = static_cast<int>(*v);
  if (const auto v = r.integer(t, "max_connections", p, 1, 32))
    s.max_connections = static_cast<int>(*v);
  s.idle_timeout = r.ms(t, "idle_timeout_ms", p, s.idle_timeout);
  if (const auto v = r.str(t, "word_order", p)) {
    if (!hal::parse_word_order(*v, s.word_order)) {
      r.fail(t.get("word_order"), p + "word_order",
             "'" + *v + "'; expected \"high_first\" or \"low_first\"");
    }
  }
  if (const toml::node* n = t.get("allow")) {
    const toml::array* a = n->as_array();
    if (!a) r.fail(n, p + "allow", "expected an array of IPv4 addresses");
    for (const auto& e : *a) {
      if (!e.is_string()) r.fail(&e, p + "allow", "expected strings (IPv4 addresses)");
      s.allow.push_back(*e.value<std::string>());
    }
  }
  if (const toml::node* n = t.get("writable")) {
    const toml::array* a = n->as_array();
    if (!a) r.fail(n, p + "writable", "expected an array of register addresses");
    for (const auto& e : *a) {
      const auto v = e.value<std::int64_t>();
      constexpr std::int64_t kFirst = app::results::RegisterMap::kCommandStart;
      constexpr std::int64_t kLast = kFirst + app::results::RegisterMap::kCommandCount - 1;
      if (!e.is_integer() || *v < kFirst || *v > kLast) {
        r.fail(&e, p + "writable",
               "expected command register addresses " + std::to_string(kFirst) + ".." +
                   std::to_string(kLast) + " (the results themselves are read-only)");
      }
      s.writable.push_back(static_cast<std::uint16_t>(*v));
    }
  }
}

}  // namespace

const char* to_string(Backend b) {
  switch (b) {
    case Backend::kNone:
      return "none";
    case Backend::kLinux:
      return "linux";
    case Backend::kReplay:
      return "replay";
    case Backend::kSim:
      return "sim";
  }
  return "?";
}

BusConfig parse_bus_config(std::string_view text, const std::filesystem::path& name) {
  toml::table root;
  try {
    root = toml::parse(text, name.string());
  } catch (const toml::parse_error& e) {
    std::ostringstream m;
    m << name.string() << ":" << e.source().begin.line << ":" << e.source().begin.column << ": "
      << e.description();
    throw BusConfigError(m.str());
  }
  const Reader r(name);
  BusConfig c;
  c.file = name;
  r.only(root, "", {"format", "scada", "cms", "keyphasor", "outputs", "results", "replay"});
  const auto format = r.str(root, "format", "");
  if (!format || *format != kBusFormat) {
    r.fail(root.get("format"), "format",
           (format ? "'" + *format + "'" : std::string("missing")) + "; expected \"" + kBusFormat +
               "\"");
  }
  if (const toml::table* t = r.table(root, "replay", "")) {
    r.only(*t, "replay.", {"bundle", "speed"});
    if (const auto s = r.str(*t, "bundle", "replay."))
      c.bundle = (name.parent_path() / *s).string();
    if (const auto v = r.number(*t, "speed", "replay.", 0.0, 1000.0)) c.replay_speed = *v;
  }
  if (const toml::table* t = r.table(root, "scada", "")) read_scada(r, *t, c);
  if (const toml::table* t = r.table(root, "cms", "")) read_cms(r, *t, c);
  if (const toml::table* t = r.table(root, "keyphasor", "")) read_keyphasor(r, *t, c);
  if (const toml::table* t = r.table(root, "outputs", "")) read_outputs(r, *t, c);
  if (const toml::table* t = r.table(root, "results", "")) read_results(r, *t, c);
  const bool replay =
      c.scada == Backend::kReplay || c.cms == Backend::kReplay || c.keyphasor == Backend::kReplay;
  if (replay && c.bundle.empty() &&
      !(c.scada == Backend::kReplay && !c.scada_csv.empty() && c.cms != Backend::kReplay &&
        c.keyphasor != Backend::kReplay)) {
    r.fail(root.get("replay"), "replay.bundle",
           "missing; a replay backend needs the recording bundle to play");
  }
  return c;
}

BusConfig load_bus_config(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw BusConfigError(file.string() + ": cannot open the bus configuration file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_bus_config(ss.str(), file);
}

}  // namespace app::bus
