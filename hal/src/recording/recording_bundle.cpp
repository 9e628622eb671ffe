// Recording bundle reader and writer (shared/reference/recording-bundle.md).
// Non-real-time. Parses without exceptions (nlohmann::json::parse with
// allow_exceptions=false, std::from_chars) so that a malformed file can only
// ever produce a BundleError, never a crash; see the fuzz targets.
#include "hal/recording_bundle.hpp"

#include "hal/scada_csv.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>
#include <system_error>

namespace hal {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kMetaFile = "recording.json";
constexpr const char* kScadaFile = "scada.csv";

BundleError error(std::string file, std::string field, std::string message) {
  return BundleError{std::move(file), std::move(field), std::move(message)};
}

std::string format_double(double v) {
  char buf[64];
  auto res = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, res.ptr);
}

bool read_file(const fs::path& path, std::string& out) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) return false;
  out = ss.str();
  return true;
}

// ---- CSV ------------------------------------------------------------------

/// Splits one CSV line on commas (no quoting: the bundle's CSV files are numeric
/// with plain identifiers in the header). Strips a trailing '\r' and blanks.
std::vector<std::string_view> split_csv(std::string_view line) {
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  std::vector<std::string_view> cells;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    std::string_view cell = line.substr(
        start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
    while (!cell.empty() && (cell.front() == ' ' || cell.front() == '\t')) cell.remove_prefix(1);
    while (!cell.empty() && (cell.back() == ' ' || cell.back() == '\t')) cell.remove_suffix(1);
    cells.push_back(cell);
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return cells;
}

bool parse_number(std::string_view cell, double& out) {
  if (cell.empty()) return false;
  if (cell.front() == '+') cell.remove_prefix(1);
  const auto res = std::from_chars(cell.data(), cell.data() + cell.size(), out);
  return res.ec == std::errc() && res.ptr == cell.data() + cell.size();
}

/// Iterates the lines of `text`, skipping blank ones; calls f(line_number, line)
/// with 1-based line numbers; stops when f returns false.
template <typename F>
void for_each_line(std::string_view text, F&& f) {
  std::size_t line_no = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t nl = text.find('\n', pos);
    if (nl == std::string_view::npos) nl = text.size();
    std::string_view line = text.substr(pos, nl - pos);
    pos = nl + 1;
    ++line_no;
    std::string_view trimmed = line;
    while (!trimmed.empty() && (trimmed.back() == '\r' || trimmed.back() == ' '))
      trimmed.remove_suffix(1);
    if (trimmed.empty()) continue;
    if (!f(line_no, line)) return;
  }
}

std::string where(std::size_t line_no, std::string_view column) {
  return "line " + std::to_string(line_no) + ", column '" + std::string(column) + "'";
}

// ---- JSON helpers ---------------------------------------------------------

std::optional<BundleError> get_string(const json& obj, const char* key, const std::string& file,
                                      const std::string& field, bool required, std::string& out) {
  const auto it = obj.find(key);
  if (it == obj.end()) {
    if (required) return error(file, field, "missing; expected a string");
    return std::nullopt;
  }
  if (!it->is_string())
    return error(file, field, "expected a string, found " + std::string(it->type_name()));
  out = it->get<std::string>();
  return std::nullopt;
}

std::optional<BundleError> get_number(const json& obj, const char* key, const std::string& file,
                                      const std::string& field, std::optional<double>& out) {
  const auto it = obj.find(key);
  if (it == obj.end() || it->is_null()) return std::nullopt;
  if (!it->is_number())
    return error(file, field, "expected a number, found " + std::string(it->type_name()));
  out = it->get<double>();
  return std::nullopt;
}

bool lower_ext_is(const std::string& name, const char* ext) {
  if (name.size() < std::strlen(ext)) return false;
  std::string tail = name.substr(name.size() - std::strlen(ext));
  std::transform(tail.begin(), tail.end(), tail.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return tail == ext;
}

// ---- WAV helpers ----------------------------------------------------------

std::uint16_t le16(const char* p) {
  return static_cast<std::uint16_t>(static_cast<unsigned char>(p[0]) |
                                    (static_cast<unsigned char>(p[1]) << 8));
}
std::uint32_t le32(const char* p) {
  return static_cast<std::uint32_t>(static_cast<unsigned char>(p[0])) |
         (static_cast<std::uint32_t>(static_cast<unsigned char>(p[1])) << 8) |
         (static_cast<std::uint32_t>(static_cast<unsigned char>(p[2])) << 16) |
         (static_cast<std::uint32_t>(static_cast<unsigned char>(p[3])) << 24);
}
void put16(std::string& s, std::uint16_t v) {
  s.push_back(static_cast<char>(v & 0xFF));
  s.push_back(static_cast<char>(v >> 8));
}
void put32(std::string& s, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}

constexpr std::uint16_t kWaveFormatIeeeFloat = 3;
constexpr std::uint16_t kWaveFormatExtensible = 0xFFFE;

}  // namespace

std::string BundleError::to_string() const {
  std::string s = file;
  if (!field.empty()) s += ": " + field;
  s += ": " + message;
  return s;
}

std::optional<UnitInfo> parse_unit(const std::string& unit) {
  struct Known {
    const char* name;
    UnitInfo info;
  };
  static constexpr double kStandardGravity = 9.80665;  // [m/s²] ISO 80000-3, CGPM 1901
  static const Known kKnown[] = {
      {"m/s^2", {UnitQuantity::kAcceleration, 1.0, "m/s^2"}},
      {"m/s\xc2\xb2", {UnitQuantity::kAcceleration, 1.0, "m/s^2"}},  // m/s²
      {"m/s2", {UnitQuantity::kAcceleration, 1.0, "m/s^2"}},
      {"g", {UnitQuantity::kAcceleration, kStandardGravity, "m/s^2"}},
      {"mm/s^2", {UnitQuantity::kAcceleration, 1e-3, "m/s^2"}},
      {"m/s", {UnitQuantity::kVelocity, 1.0, "m/s"}},
      {"mm/s", {UnitQuantity::kVelocity, 1e-3, "m/s"}},
      {"m", {UnitQuantity::kDisplacement, 1.0, "m"}},
      {"mm", {UnitQuantity::kDisplacement, 1e-3, "m"}},
      {"um", {UnitQuantity::kDisplacement, 1e-6, "m"}},
      {"\xc2\xb5m", {UnitQuantity::kDisplacement, 1e-6, "m"}},  // µm
      {"V", {UnitQuantity::kVoltage, 1.0, "V"}},
      {"mV", {UnitQuantity::kVoltage, 1e-3, "V"}},
  };
  for (const Known& k : kKnown) {
    if (unit == k.name) return k.info;
  }
  return std::nullopt;
}

const char* known_units() {
  return "m/s^2, m/s2, g, mm/s^2 (acceleration), m/s, mm/s (velocity), m, mm, um "
         "(displacement), V, mV (voltage)";
}

std::optional<std::size_t> Recording::channel_index(const std::string& name) const {
  for (std::size_t i = 0; i < channels.size(); ++i)
    if (channels[i].name == name) return i;
  return std::nullopt;
}

// ---- recording.json -------------------------------------------------------

std::optional<BundleError> parse_recording_json(const std::string& text, const std::string& file,
                                                Recording& rec) {
  const json doc = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded())
    return error(file, "", "not valid JSON; expected a JSON object (recording-bundle.md)");
  if (!doc.is_object()) return error(file, "", "expected a JSON object at the top level");

  std::string format;
  if (auto e = get_string(doc, "format", file, "format", true, format)) return e;
  if (format != kRecordingFormat) {
    return error(file, "format",
                 "unknown format '" + format + "'; expected '" + kRecordingFormat + "'");
  }

  if (auto e = get_string(doc, "drivetrain", file, "drivetrain", true, rec.drivetrain)) return e;
  if (rec.drivetrain.empty())
    return error(file, "drivetrain", "empty; expected a drivetrain name or a path");

  std::optional<double> fs_hz;
  if (auto e = get_number(doc, "sample_rate_hz", file, "sample_rate_hz", fs_hz)) return e;
  if (!fs_hz) return error(file, "sample_rate_hz", "missing; expected a number > 0");
  rec.sample_rate_hz = *fs_hz;

  if (auto e = get_string(doc, "samples", file, "samples", true, rec.samples_file)) return e;

  const auto ch = doc.find("channels");
  if (ch == doc.end())
    return error(file, "channels", "missing; expected an array of channel objects");
  if (!ch->is_array())
    return error(file, "channels", "expected an array, found " + std::string(ch->type_name()));
  rec.channels.clear();
  for (std::size_t i = 0; i < ch->size(); ++i) {
    const json& c = (*ch)[i];
    const std::string field = "channels[" + std::to_string(i) + "]";
    if (!c.is_object())
      return error(file, field, "expected an object, found " + std::string(c.type_name()));
    BundleChannel out;
    if (auto e = get_string(c, "name", file, field + ".name", true, out.name)) return e;
    if (auto e = get_string(c, "location", file, field + ".location", true, out.location)) return e;
    if (auto e = get_string(c, "direction", file, field + ".direction", false, out.direction))
      return e;
    if (auto e = get_string(c, "kind", file, field + ".kind", false, out.kind)) return e;
    if (auto e = get_string(c, "unit", file, field + ".unit", true, out.unit)) return e;
    rec.channels.push_back(std::move(out));
  }

  const auto op = doc.find("operating_point");
  if (op == doc.end())
    return error(file, "operating_point", "missing; expected an object with rotor_speed_rpm");
  if (!op->is_object()) {
    return error(file, "operating_point",
                 "expected an object, found " + std::string(op->type_name()));
  }
  std::optional<double> rpm;
  if (auto e = get_number(*op, "rotor_speed_rpm", file, "operating_point.rotor_speed_rpm", rpm))
    return e;
  if (!rpm)
    return error(file, "operating_point.rotor_speed_rpm", "missing; expected a number (rpm)");
  rec.operating_point.rotor_speed_rpm = *rpm;
  if (auto e = get_number(*op, "wind_speed_mps", file, "operating_point.wind_speed_mps",
                          rec.operating_point.wind_speed_mps))
    return e;
  if (auto e = get_number(*op, "input_torque_nm", file, "operating_point.input_torque_nm",
                          rec.operating_point.input_torque_nm))
    return e;

  if (auto e = get_string(doc, "start_utc", file, "start_utc", false, rec.start_utc)) return e;
  if (auto e = get_string(doc, "notes", file, "notes", false, rec.notes)) return e;
  return std::nullopt;
}

// ---- validation -----------------------------------------------------------

namespace {

std::optional<BundleError> validate_metadata(const Recording& rec, const OperatingRange& range,
                                             const std::string& file) {
  if (!std::isfinite(rec.sample_rate_hz) || rec.sample_rate_hz <= 0.0) {
    return error(file, "sample_rate_hz",
                 "is " + format_double(rec.sample_rate_hz) + "; expected a finite number > 0");
  }
  if (rec.samples_file.empty() || rec.samples_file.find('/') != std::string::npos ||
      rec.samples_file.find('\\') != std::string::npos || rec.samples_file == "." ||
      rec.samples_file == "..") {
    return error(file, "samples",
                 "'" + rec.samples_file + "'; expected a file name inside the bundle");
  }
  if (!lower_ext_is(rec.samples_file, ".wav") && !lower_ext_is(rec.samples_file, ".csv"))
    return error(file, "samples", "'" + rec.samples_file + "'; expected a .wav or .csv file");
  if (rec.channels.empty()) return error(file, "channels", "empty; expected at least one channel");
  std::set<std::string> names;
  for (std::size_t i = 0; i < rec.channels.size(); ++i) {
    const BundleChannel& c = rec.channels[i];
    const std::string field = "channels[" + std::to_string(i) + "]";
    if (c.name.empty() || c.name == "t_s" || c.name.find(',') != std::string::npos) {
      return error(file, field + ".name",
                   "'" + c.name + "'; expected a non-empty name other than t_s, without commas");
    }
    if (!names.insert(c.name).second)
      return error(file, field + ".name", "'" + c.name + "' repeats; expected unique names");
    if (c.location.empty())
      return error(file, field + ".location", "empty; expected a component id");
    if (c.unit.empty()) return error(file, field + ".unit", "empty; expected a unit such as m/s^2");
    const auto unit = parse_unit(c.unit);
    if (!unit) {
      return error(
          file, field + ".unit",
          "'" + c.unit + "' is not a unit the project knows; expected one of " + known_units());
    }
    if (!c.kind.empty() && c.kind != "once_per_rev") {
      return error(file, field + ".kind",
                   "'" + c.kind + "'; expected \"once_per_rev\" (a tacho) or no kind");
    }
    if (c.kind == "once_per_rev" && unit->quantity != UnitQuantity::kVoltage) {
      return error(
          file, field + ".unit",
          "'" + c.unit + "' for a once_per_rev (tacho) channel; expected a voltage (V, mV)");
    }
  }
  const BundleOperatingPoint& op = rec.operating_point;
  auto check = [&](const char* field, double v, double max,
                   const char* unit) -> std::optional<BundleError> {
    if (!std::isfinite(v) || v < 0.0 || (max > 0.0 && v > max)) {
      std::string expected = "expected a finite value >= 0";
      if (max > 0.0)
        expected += " and <= " + format_double(max) + " " + unit + " (the turbine's range)";
      return error(file, std::string("operating_point.") + field,
                   "is " + format_double(v) + "; " + expected);
    }
    return std::nullopt;
  };
  if (auto e = check("rotor_speed_rpm", op.rotor_speed_rpm, range.max_rotor_speed_rpm, "rpm"))
    return e;
  if (!op.wind_speed_mps && !op.input_torque_nm) {
    return error(file, "operating_point",
                 "has neither input_torque_nm nor wind_speed_mps; expected at least one");
  }
  if (op.wind_speed_mps) {
    if (auto e = check("wind_speed_mps", *op.wind_speed_mps, range.max_wind_speed_mps, "m/s"))
      return e;
  }
  if (op.input_torque_nm) {
    if (auto e = check("input_torque_nm", *op.input_torque_nm, range.max_input_torque_nm, "N·m"))
      return e;
  }
  return std::nullopt;
}

}  // namespace

std::optional<BundleError> validate_recording(const Recording& rec, const OperatingRange& range) {
  if (auto e = validate_metadata(rec, range, kMetaFile)) return e;
  const std::string& sf = rec.samples_file;
  if (rec.samples.size() != rec.channels.size()) {
    return error(sf, "channels",
                 std::to_string(rec.samples.size()) + " sample columns; expected " +
                     std::to_string(rec.channels.size()) + " (one per channel)");
  }
  const std::size_t n = rec.sample_count();
  if (n == 0) return error(sf, "", "no samples; expected at least one");
  for (std::size_t c = 0; c < rec.samples.size(); ++c) {
    if (rec.samples[c].size() != n) {
      return error(sf, rec.channels[c].name,
                   std::to_string(rec.samples[c].size()) + " samples; expected " +
                       std::to_string(n) + " like the first channel");
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite(rec.samples[c][i])) {
        return error(sf, rec.channels[c].name + " sample " + std::to_string(i),
                     "non-finite; expected a finite number");
      }
    }
    if (lower_ext_is(sf, ".wav")) {
      for (std::size_t i = 0; i < n; ++i) {
        if (std::fabs(rec.samples[c][i]) > static_cast<double>(std::numeric_limits<float>::max())) {
          return error(sf, rec.channels[c].name + " sample " + std::to_string(i),
                       "exceeds the float32 range of a WAV file");
        }
      }
    }
  }
  double last_t = -1.0;
  for (std::size_t i = 0; i < rec.scada.size(); ++i) {
    const BundleScadaRow& s = rec.scada[i];
    const std::string field = "row " + std::to_string(i + 1);
    if (!std::isfinite(s.t_s) || s.t_s <= last_t) {
      return error(kScadaFile, field + ", column 't_s'",
                   "is " + format_double(s.t_s) + "; expected finite and increasing");
    }
    last_t = s.t_s;
    const std::optional<double> vals[] = {s.wind_speed_mps, s.rotor_speed_rpm, s.power_kw,
                                          s.pitch_deg, s.torque_nm};
    for (const auto& v : vals) {
      if (v && !std::isfinite(*v))
        return error(kScadaFile, field, "non-finite value; expected finite numbers");
    }
  }
  return std::nullopt;
}

// ---- WAV ------------------------------------------------------------------

std::optional<BundleError> parse_wav(const std::string& bytes, const std::string& file,
                                     WavData& out) {
  if (bytes.size() < 12 || std::memcmp(bytes.data(), "RIFF", 4) != 0 ||
      std::memcmp(bytes.data() + 8, "WAVE", 4) != 0) {
    return error(file, "RIFF header",
                 "not a RIFF/WAVE file; expected a WAV file of IEEE float 32-bit samples");
  }
  bool have_fmt = false;
  std::size_t pos = 12;
  while (pos + 8 <= bytes.size()) {
    const char* id = bytes.data() + pos;
    const std::uint32_t size = le32(id + 4);
    const std::size_t body = pos + 8;
    const std::size_t avail = bytes.size() - body;
    if (std::memcmp(id, "fmt ", 4) == 0) {
      if (size < 16 || size > avail)
        return error(file, "fmt chunk", "truncated; expected at least 16 bytes");
      const char* p = bytes.data() + body;
      std::uint16_t format = le16(p);
      out.channels = le16(p + 2);
      out.sample_rate_hz = le32(p + 4);
      const std::uint16_t block_align = le16(p + 12);
      const std::uint16_t bits = le16(p + 14);
      if (format == kWaveFormatExtensible) {
        // WAVEFORMATEXTENSIBLE: cbSize(2) validBits(2) channelMask(4) subFormat GUID (first 2 bytes
        // = format).
        if (size < 40)
          return error(file, "fmt chunk", "WAVE_FORMAT_EXTENSIBLE chunk shorter than 40 bytes");
        format = le16(p + 24);
      }
      if (format != kWaveFormatIeeeFloat || bits != 32) {
        return error(file, "fmt chunk",
                     "format " + std::to_string(format) + " with " + std::to_string(bits) +
                         " bits; expected IEEE float (3) with 32 bits");
      }
      if (out.channels == 0) return error(file, "fmt chunk", "0 channels; expected at least one");
      if (block_align != out.channels * 4u) {
        return error(file, "fmt chunk",
                     "block align " + std::to_string(block_align) + "; expected " +
                         std::to_string(out.channels * 4u) + " (4 bytes x channels)");
      }
      have_fmt = true;
    } else if (std::memcmp(id, "data", 4) == 0) {
      if (!have_fmt)
        return error(file, "data chunk", "comes before the fmt chunk; expected fmt first");
      if (size > avail) {
        return error(file, "data chunk",
                     "declares " + std::to_string(size) + " bytes but only " +
                         std::to_string(avail) + " follow; file truncated");
      }
      const std::size_t frame = out.channels * 4u;
      if (size % frame != 0) {
        return error(file, "data chunk",
                     std::to_string(size) + " bytes is not a whole number of " +
                         std::to_string(frame) + "-byte frames");
      }
      out.interleaved.resize(size / 4);
      for (std::size_t i = 0; i < out.interleaved.size(); ++i) {
        const std::uint32_t bits32 = le32(bytes.data() + body + 4 * i);
        float f;
        std::memcpy(&f, &bits32, sizeof f);
        out.interleaved[i] = f;
      }
      return std::nullopt;
    }
    if (size > avail) break;
    pos = body + size + (size & 1u);  // chunks are padded to even sizes
  }
  return error(file, have_fmt ? "data chunk" : "fmt chunk",
               "missing; expected fmt and data chunks");
}

// ---- CSV ------------------------------------------------------------------

std::optional<BundleError> parse_samples_csv(const std::string& text, const std::string& file,
                                             const std::vector<BundleChannel>& channels,
                                             double sample_rate_hz,
                                             std::vector<std::vector<double>>& out) {
  std::optional<BundleError> err;
  std::vector<std::optional<std::size_t>> column_of;  // CSV column -> channel index
  std::size_t t_col = 0;
  std::vector<std::string> header;
  double t0 = 0.0;
  std::size_t row = 0;
  out.assign(channels.size(), {});
  for_each_line(text, [&](std::size_t line_no, std::string_view line) {
    const auto cells = split_csv(line);
    if (header.empty()) {
      for (auto c : cells) header.emplace_back(c);
      if (header.front() != "t_s") {
        err = error(file, "line 1, column 1",
                    "'" + header.front() + "'; expected the header to start with t_s");
        return false;
      }
      std::vector<bool> found(channels.size(), false);
      column_of.assign(header.size(), std::nullopt);
      for (std::size_t k = 0; k < header.size(); ++k) {
        for (std::size_t c = 0; c < channels.size(); ++c) {
          if (header[k] == channels[c].name) {
            if (found[c]) {
              err =
                  error(file, "line 1", "column '" + header[k] + "' appears twice; expected once");
              return false;
            }
            found[c] = true;
            column_of[k] = c;
          }
        }
      }
      for (std::size_t c = 0; c < channels.size(); ++c) {
        if (!found[c]) {
          err = error(file, "line 1",
                      "no column '" + channels[c].name +
                          "'; expected one column per channel of recording.json");
          return false;
        }
      }
      t_col = 0;
      return true;
    }
    if (cells.size() != header.size()) {
      err = error(file, "line " + std::to_string(line_no),
                  std::to_string(cells.size()) + " fields; expected " +
                      std::to_string(header.size()) + " like the header");
      return false;
    }
    double t = 0.0;
    if (!parse_number(cells[t_col], t) || !std::isfinite(t)) {
      err = error(file, where(line_no, "t_s"),
                  "'" + std::string(cells[t_col]) + "'; expected a finite number");
      return false;
    }
    if (row == 0) t0 = t;
    const double expected_t = t0 + static_cast<double>(row) / sample_rate_hz;
    if (std::fabs(t - expected_t) > 0.5 / sample_rate_hz) {
      err = error(file, where(line_no, "t_s"),
                  format_double(t) + "; expected " + format_double(expected_t) +
                      " (uniform sampling at sample_rate_hz)");
      return false;
    }
    for (std::size_t k = 0; k < cells.size(); ++k) {
      if (!column_of[k]) continue;
      double v = 0.0;
      if (!parse_number(cells[k], v) || !std::isfinite(v)) {
        err = error(file, where(line_no, header[k]),
                    "'" + std::string(cells[k]) + "'; expected a finite number");
        return false;
      }
      out[*column_of[k]].push_back(v);
    }
    ++row;
    return true;
  });
  if (err) return err;
  if (header.empty())
    return error(file, "line 1", "empty file; expected a header row t_s,<channel names>");
  if (row == 0) return error(file, "", "no sample rows; expected at least one");
  return std::nullopt;
}

std::optional<BundleError> parse_scada_csv(const std::string& text, const std::string& file,
                                           std::vector<BundleScadaRow>& out) {
  // The streaming SCADA reader of hal/scada_csv.hpp with the bundle's column
  // names; this adds the bundle's rules: time and wind speed in every row, time
  // increasing. Its messages start with "<file>: "; BundleError carries the file apart.
  auto strip_file = [&](const std::string& m) {
    const std::string prefix = file + ": ";
    return m.rfind(prefix, 0) == 0 ? m.substr(prefix.size()) : m;
  };
  out.clear();
  ScadaCsvReader reader;
  if (!reader.open_text(text, file, bundle_scada_columns())) {
    return error(
        file, "header",
        strip_file(reader.error()) +
            "; expected t_s,wind_speed_mps[,rotor_speed_rpm,power_kw,pitch_deg,torque_nm]");
  }
  ScadaRow row;
  while (true) {
    const ScadaReadResult res = reader.next(row);
    if (res == ScadaReadResult::kEnd) break;
    if (res == ScadaReadResult::kError) return error(file, "", strip_file(reader.error()));
    const std::string at =
        "row " + std::to_string(row.row) + " (line " + std::to_string(row.line) + ")";
    if (!row.has_time()) {
      return error(file, at + ", column 't_s'", "empty; expected a number in every row");
    }
    if (!row.has(ScadaQuantity::kWindSpeed)) {
      return error(file, at + ", column 'wind_speed_mps'", "empty; expected a number in every row");
    }
    BundleScadaRow r;
    r.t_s = row.time_s();
    r.wind_speed_mps = row.get(ScadaQuantity::kWindSpeed);
    if (!out.empty() && r.t_s <= out.back().t_s) {
      return error(file, at + ", column 't_s'",
                   format_double(r.t_s) + "; expected t_s to increase from row to row");
    }
    auto opt = [&](ScadaQuantity f) {
      return row.has(f) ? std::optional<double>(row.get(f)) : std::nullopt;
    };
    r.rotor_speed_rpm = opt(ScadaQuantity::kRotorSpeed);
    r.power_kw = opt(ScadaQuantity::kPower);
    r.pitch_deg = opt(ScadaQuantity::kPitch);
    r.torque_nm = opt(ScadaQuantity::kRotorTorque);
    out.push_back(r);
  }
  return std::nullopt;
}

// ---- read -----------------------------------------------------------------

BundleReadResult read_bundle(const fs::path& dir, const OperatingRange& range) {
  BundleReadResult result;
  auto fail = [&](BundleError e) {
    result.error = std::move(e);
    return result;
  };
  const fs::path meta_path = dir / kMetaFile;
  const std::string meta_name = meta_path.string();
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    return fail(error(dir.string(), "", "not a directory; expected a recording bundle directory"));
  std::string text;
  if (!fs::is_regular_file(meta_path, ec) || !read_file(meta_path, text))
    return fail(error(meta_name, "", "missing or unreadable; every bundle needs recording.json"));

  Recording rec;
  if (auto e = parse_recording_json(text, meta_name, rec)) return fail(*e);
  if (auto e = validate_metadata(rec, range, meta_name)) return fail(*e);

  const fs::path samples_path = dir / rec.samples_file;
  const std::string samples_name = samples_path.string();
  std::string data;
  if (!fs::is_regular_file(samples_path, ec) || !read_file(samples_path, data)) {
    return fail(
        error(samples_name, "", "missing or unreadable; recording.json field 'samples' names it"));
  }

  if (lower_ext_is(rec.samples_file, ".wav")) {
    WavData wav;
    if (auto e = parse_wav(data, samples_name, wav)) return fail(*e);
    if (wav.channels != rec.channels.size()) {
      return fail(error(samples_name, "fmt chunk",
                        std::to_string(wav.channels) + " channels; expected " +
                            std::to_string(rec.channels.size()) + " (recording.json channels)"));
    }
    if (std::fabs(static_cast<double>(wav.sample_rate_hz) - rec.sample_rate_hz) > 0.5) {
      return fail(error(samples_name, "fmt chunk",
                        "sample rate " + std::to_string(wav.sample_rate_hz) + " Hz; expected " +
                            format_double(rec.sample_rate_hz) +
                            " Hz (recording.json sample_rate_hz)"));
    }
    const std::size_t frames = wav.interleaved.size() / wav.channels;
    if (frames == 0)
      return fail(error(samples_name, "data chunk", "no samples; expected at least one frame"));
    rec.samples.assign(wav.channels, std::vector<double>(frames));
    for (std::size_t i = 0; i < frames; ++i) {
      for (std::size_t c = 0; c < wav.channels; ++c) {
        const float v = wav.interleaved[i * wav.channels + c];
        if (!std::isfinite(v)) {
          return fail(error(samples_name,
                            "channel '" + rec.channels[c].name + "' frame " + std::to_string(i),
                            "non-finite sample; expected finite numbers"));
        }
        rec.samples[c][i] = static_cast<double>(v);
      }
    }
  } else {
    if (auto e =
            parse_samples_csv(data, samples_name, rec.channels, rec.sample_rate_hz, rec.samples))
      return fail(*e);
  }

  // Every channel in the SI unit of its quantity (validate_metadata refused unknown units).
  for (std::size_t c = 0; c < rec.channels.size(); ++c) {
    BundleChannel& ch = rec.channels[c];
    const UnitInfo unit = *parse_unit(ch.unit);
    if (ch.unit == unit.si_unit) continue;
    if (unit.to_si != 1.0) {
      for (double& v : rec.samples[c]) v *= unit.to_si;
    }
    result.notes.push_back("channels[" + std::to_string(c) + "] '" + ch.name +
                           "': converted from " + ch.unit + " to " + unit.si_unit + " (x " +
                           format_double(unit.to_si) + ")");
    ch.unit = unit.si_unit;
  }

  const fs::path scada_path = dir / kScadaFile;
  if (fs::exists(scada_path, ec)) {
    std::string scada;
    if (!read_file(scada_path, scada)) return fail(error(scada_path.string(), "", "unreadable"));
    if (auto e = parse_scada_csv(scada, scada_path.string(), rec.scada)) return fail(*e);
  }
  result.recording = std::move(rec);
  return result;
}

// ---- write ----------------------------------------------------------------

namespace {

std::string make_json(const Recording& rec) {
  json doc;
  doc["format"] = kRecordingFormat;
  doc["drivetrain"] = rec.drivetrain;
  doc["sample_rate_hz"] = rec.sample_rate_hz;
  doc["samples"] = rec.samples_file;
  json chans = json::array();
  for (const auto& c : rec.channels) {
    json j{{"name", c.name}, {"location", c.location}, {"unit", c.unit}};
    if (!c.direction.empty()) j["direction"] = c.direction;
    if (!c.kind.empty()) j["kind"] = c.kind;
    chans.push_back(std::move(j));
  }
  doc["channels"] = std::move(chans);
  json op{{"rotor_speed_rpm", rec.operating_point.rotor_speed_rpm}};
  if (rec.operating_point.wind_speed_mps)
    op["wind_speed_mps"] = *rec.operating_point.wind_speed_mps;
  if (rec.operating_point.input_torque_nm)
    op["input_torque_nm"] = *rec.operating_point.input_torque_nm;
  doc["operating_point"] = std::move(op);
  if (!rec.start_utc.empty()) doc["start_utc"] = rec.start_utc;
  if (!rec.notes.empty()) doc["notes"] = rec.notes;
  return doc.dump(2) + "\n";
}

std::string make_wav(const Recording& rec) {
  const auto channels = static_cast<std::uint16_t>(rec.channels.size());
  const std::size_t frames = rec.sample_count();
  const auto data_bytes = static_cast<std::uint32_t>(frames * channels * 4u);
  std::string s;
  s.reserve(44 + data_bytes);
  s += "RIFF";
  put32(s, 36 + data_bytes);
  s += "WAVEfmt ";
  put32(s, 16);
  put16(s, kWaveFormatIeeeFloat);
  put16(s, channels);
  put32(s, static_cast<std::uint32_t>(std::lround(rec.sample_rate_hz)));
  put32(s, static_cast<std::uint32_t>(std::lround(rec.sample_rate_hz)) * channels * 4u);
  put16(s, static_cast<std::uint16_t>(channels * 4u));
  put16(s, 32);
  s += "data";
  put32(s, data_bytes);
  for (std::size_t i = 0; i < frames; ++i) {
    for (std::size_t c = 0; c < channels; ++c) {
      const auto f = static_cast<float>(rec.samples[c][i]);
      std::uint32_t bits;
      std::memcpy(&bits, &f, sizeof bits);
      put32(s, bits);
    }
  }
  return s;
}

void append_double(std::string& s, double v) {
  char buf[32];
  auto res = std::to_chars(buf, buf + sizeof buf, v);  // shortest round-trip representation
  s.append(buf, res.ptr);
}

std::string make_samples_csv(const Recording& rec) {
  std::string s = "t_s";
  for (const auto& c : rec.channels) s += "," + c.name;
  s += "\n";
  for (std::size_t i = 0; i < rec.sample_count(); ++i) {
    append_double(s, static_cast<double>(i) / rec.sample_rate_hz);
    for (const auto& col : rec.samples) {
      s += ",";
      append_double(s, col[i]);
    }
    s += "\n";
  }
  return s;
}

std::string make_scada_csv(const Recording& rec) {
  bool rpm = false, power = false, pitch = false, torque = false;
  for (const auto& r : rec.scada) {
    rpm |= r.rotor_speed_rpm.has_value();
    power |= r.power_kw.has_value();
    pitch |= r.pitch_deg.has_value();
    torque |= r.torque_nm.has_value();
  }
  std::string s = "t_s,wind_speed_mps";
  if (rpm) s += ",rotor_speed_rpm";
  if (power) s += ",power_kw";
  if (pitch) s += ",pitch_deg";
  if (torque) s += ",torque_nm";
  s += "\n";
  auto opt = [&](bool present, const std::optional<double>& v) {
    if (!present) return;
    s += ",";
    append_double(s, v.value_or(std::nan("")));
  };
  for (const auto& r : rec.scada) {
    append_double(s, r.t_s);
    s += ",";
    append_double(s, r.wind_speed_mps);
    opt(rpm, r.rotor_speed_rpm);
    opt(power, r.power_kw);
    opt(pitch, r.pitch_deg);
    opt(torque, r.torque_nm);
    s += "\n";
  }
  return s;
}

bool write_file(const fs::path& path, const std::string& bytes) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return false;
  const bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
  return (std::fclose(f) == 0) && ok;
}

}  // namespace

std::optional<BundleError> write_bundle(const fs::path& dir, const Recording& rec,
                                        const OperatingRange& range) {
  if (auto e = validate_recording(rec, range)) return e;
  if (lower_ext_is(rec.samples_file, ".wav") && rec.channels.size() > 0xFFFFu / 4u)
    return error(rec.samples_file, "channels", "too many channels for a WAV file");
  if (rec.scada.size() > 0) {
    // A row that leaves out a column others carry cannot be written as CSV.
    const BundleScadaRow& f = rec.scada.front();
    for (std::size_t i = 0; i < rec.scada.size(); ++i) {
      const BundleScadaRow& r = rec.scada[i];
      if (r.rotor_speed_rpm.has_value() != f.rotor_speed_rpm.has_value() ||
          r.power_kw.has_value() != f.power_kw.has_value() ||
          r.pitch_deg.has_value() != f.pitch_deg.has_value() ||
          r.torque_nm.has_value() != f.torque_nm.has_value()) {
        return error(
            kScadaFile, "row " + std::to_string(i + 1),
            "has a different set of columns than row 1; expected the same columns in every row");
      }
    }
  }

  struct Part {
    std::string name;
    std::string bytes;
  };
  // recording.json goes last: a directory without it is not a bundle, so a
  // failure between two renames cannot leave a readable half-bundle behind.
  std::vector<Part> parts;
  parts.push_back({rec.samples_file,
                   lower_ext_is(rec.samples_file, ".wav") ? make_wav(rec) : make_samples_csv(rec)});
  if (!rec.scada.empty()) parts.push_back({kScadaFile, make_scada_csv(rec)});
  parts.push_back({kMetaFile, make_json(rec)});

  std::error_code ec;
  const bool existed = fs::exists(dir, ec);
  if (!existed && !fs::create_directories(dir, ec))
    return error(dir.string(), "", "cannot create the bundle directory: " + ec.message());
  const std::string tmp_suffix = ".tmp-writing";
  auto cleanup = [&]() {
    for (const auto& p : parts) fs::remove(dir / (p.name + tmp_suffix), ec);
    if (!existed) fs::remove(dir, ec);
  };
  for (const auto& p : parts) {
    if (!write_file(dir / (p.name + tmp_suffix), p.bytes)) {
      cleanup();
      return error((dir / p.name).string(), "",
                   "cannot write the file (disk full or no permission)");
    }
  }
  for (const auto& p : parts) {
    fs::rename(dir / (p.name + tmp_suffix), dir / p.name, ec);
    if (ec) {
      const std::string msg = ec.message();
      cleanup();
      return error((dir / p.name).string(), "", "cannot rename into place: " + msg);
    }
  }
  return std::nullopt;
}

}  // namespace hal
