#include "hal/scada_csv.hpp"

#include <charconv>
#include <cmath>
#include <limits>
#include <vector>

namespace hal {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

// Splits one CSV line (RFC 4180 quoting; a quoted field cannot span lines).
bool split_csv(std::string_view line, std::vector<std::string>& fields) {
  fields.clear();
  std::string field;
  bool quoted = false;
  bool was_quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char ch = line[i];
    if (quoted) {
      if (ch == '"') {
        if (i + 1 < line.size() && line[i + 1] == '"') {
          field.push_back('"');
          ++i;
        } else {
          quoted = false;
        }
      } else {
        field.push_back(ch);
      }
    } else if (ch == '"') {
      quoted = true;
      was_quoted = true;
    } else if (ch == ',') {
      fields.push_back(was_quoted ? field : std::string(trim(field)));
      field.clear();
      was_quoted = false;
    } else {
      field.push_back(ch);
    }
  }
  fields.push_back(was_quoted ? field : std::string(trim(field)));
  return !quoted;
}

bool parse_int(std::string_view s, int& out) {
  const auto r = std::from_chars(s.data(), s.data() + s.size(), out);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

// Days since 1970-01-01 of a proleptic Gregorian date (H. Hinnant, "chrono-Compatible
// Low-Level Date Algorithms", days_from_civil).
long long days_from_civil(int y, int m, int d) {
  y -= m <= 2 ? 1 : 0;
  const int era = (y >= 0 ? y : y - 399) / 400;
  const int yoe = y - era * 400;
  const int doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const int doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return static_cast<long long>(era) * 146097 + doe - 719468;
}

}  // namespace

ScadaColumns bundle_scada_columns() {
  ScadaColumns c;
  c.time = kScadaTimeKey;
  for (std::size_t i = 0; i < kScadaQuantityCount; ++i) c.quantity[i] = kScadaQuantities[i].key;
  return c;
}

ScadaColumns kelmarsh_scada_columns() {
  ScadaColumns c;
  c.time = "Date and time";
  auto set = [&c](ScadaQuantity q, const char* column) {
    c.quantity[static_cast<std::size_t>(q)] = column;
  };
  set(ScadaQuantity::kWindSpeed, "Wind speed (m/s)");
  set(ScadaQuantity::kRotorSpeed, "Rotor speed (RPM)");
  set(ScadaQuantity::kPower, "Power (kW)");
  set(ScadaQuantity::kPitch, "Pitch angle (\u00b0)");
  set(ScadaQuantity::kAmbientTemperature, "Nacelle ambient temperature (\u00b0C)");
  set(ScadaQuantity::kYawError, "Yaw error (\u00b0)");
  return c;
}

std::optional<ScadaColumns> parse_scada_columns(std::string_view spec, std::string* error) {
  const std::string_view s = trim(spec);
  if (s == "bundle" || s.empty()) return bundle_scada_columns();
  if (s == "kelmarsh") return kelmarsh_scada_columns();
  ScadaColumns columns = bundle_scada_columns();
  std::size_t start = 0;
  while (start <= s.size()) {
    std::size_t end = s.find(';', start);
    if (end == std::string_view::npos) end = s.size();
    const std::string_view item = trim(s.substr(start, end - start));
    start = end + 1;
    if (item.empty()) continue;
    const std::size_t eq = item.find('=');
    if (eq == std::string_view::npos) {
      *error = "column mapping '" + std::string(item) +
               "': expected field=Column name (or a preset: bundle, kelmarsh)";
      return std::nullopt;
    }
    const std::string_view field = trim(item.substr(0, eq));
    const std::string_view column = trim(item.substr(eq + 1));
    ScadaQuantity q{};
    if (field == kScadaTimeKey) {
      columns.time = std::string(column);
    } else if (scada_quantity_from_key(field, q)) {
      columns.quantity[static_cast<std::size_t>(q)] = std::string(column);
    } else {
      std::string known(kScadaTimeKey);
      for (const ScadaQuantityInfo& i : kScadaQuantities) known += ", " + std::string(i.key);
      *error = "column mapping: unknown field '" + std::string(field) + "' (expected one of " +
               known + ")";
      return std::nullopt;
    }
  }
  return columns;
}

std::optional<double> parse_utc_datetime_s(std::string_view text) {
  std::string_view t = trim(text);
  if (!t.empty() && t.back() == 'Z') t.remove_suffix(1);
  // YYYY-MM-DD HH:MM:SS
  if (t.size() != 19 || t[4] != '-' || t[7] != '-' || (t[10] != ' ' && t[10] != 'T') ||
      t[13] != ':' || t[16] != ':') {
    return std::nullopt;
  }
  int y = 0, mo = 0, d = 0, h = 0, mi = 0, sec = 0;
  if (!parse_int(t.substr(0, 4), y) || !parse_int(t.substr(5, 2), mo) ||
      !parse_int(t.substr(8, 2), d) || !parse_int(t.substr(11, 2), h) ||
      !parse_int(t.substr(14, 2), mi) || !parse_int(t.substr(17, 2), sec)) {
    return std::nullopt;
  }
  if (mo < 1 || mo > 12 || d < 1 || d > 31 || h > 23 || mi > 59 || sec > 60) return std::nullopt;
  return static_cast<double>(days_from_civil(y, mo, d) * 86400LL + h * 3600LL + mi * 60LL + sec);
}

bool ScadaCsvReader::open(const std::string& path, const ScadaColumns& columns) {
  path_ = path;
  columns_ = columns;
  file_.close();
  file_.clear();
  file_.open(path, std::ios::binary);
  in_ = &file_;
  if (!file_) {
    error_ = path + ": cannot open for reading";
    return false;
  }
  return read_header();
}

bool ScadaCsvReader::open_text(std::string_view text, const std::string& name,
                               const ScadaColumns& columns) {
  path_ = name;
  columns_ = columns;
  memory_.clear();
  memory_.str(std::string(text));
  in_ = &memory_;
  return read_header();
}

bool ScadaCsvReader::read_header() {
  index_.fill(-1);
  line_ = 0;
  row_ = 0;
  error_.clear();
  if (!std::getline(*in_, text_)) {
    error_ = path_ + ": empty file, expected a header row";
    return false;
  }
  line_ = 1;
  std::string_view header = text_;
  if (header.substr(0, 3) == "\xEF\xBB\xBF") header.remove_prefix(3);  // UTF-8 BOM
  std::vector<std::string> names;
  if (!split_csv(header, names)) {
    error_ = path_ + ": header: unterminated quote";
    return false;
  }
  header_fields_ = names.size();
  auto find = [&names](const std::string& column) {
    if (column.empty()) return -1;
    for (std::size_t i = 0; i < names.size(); ++i) {
      if (names[i] == column) return static_cast<int>(i);
    }
    return -1;
  };
  index_.fill(-1);
  for (std::size_t q = 0; q < kScadaQuantityCount; ++q) index_[q] = find(columns_.quantity[q]);
  time_index_ = find(columns_.time);
  auto missing = [&](const std::string& column, std::string_view key) {
    error_ = path_ + ": header: missing column '" + (column.empty() ? std::string(key) : column) +
             "' (" + std::string(key) + ", required)";
    return false;
  };
  if (time_index_ < 0) return missing(columns_.time, kScadaTimeKey);
  const auto wind = static_cast<std::size_t>(ScadaQuantity::kWindSpeed);
  if (index_[wind] < 0) return missing(columns_.quantity[wind], kScadaQuantities[wind].key);
  return true;
}

ScadaReadResult ScadaCsvReader::next(ScadaRow& row) {
  std::vector<std::string>& fields = fields_;
  while (std::getline(*in_, text_)) {
    ++line_;
    if (trim(text_).empty()) continue;
    ++row_;
    auto where = [&](const std::string& column) {
      return path_ + ": row " + std::to_string(row_) + " (line " + std::to_string(line_) +
             "), column '" + column + "'";
    };
    if (!split_csv(text_, fields)) {
      error_ = path_ + ": row " + std::to_string(row_) + " (line " + std::to_string(line_) +
               "): unterminated quote";
      return ScadaReadResult::kError;
    }
    if (fields.size() != header_fields_) {
      error_ = path_ + ": row " + std::to_string(row_) + " (line " + std::to_string(line_) +
               "): " + std::to_string(fields.size()) + " fields, expected " +
               std::to_string(header_fields_) + " as in the header";
      return ScadaReadResult::kError;
    }
    row.row = row_;
    row.line = line_;
    // Time: a number of seconds or a date-time.
    row.t_s = std::numeric_limits<double>::quiet_NaN();
    row.time_present = false;
    if (const std::string& cell = fields[static_cast<std::size_t>(time_index_)]; !cell.empty()) {
      double v = 0.0;
      const auto r = std::from_chars(cell.data(), cell.data() + cell.size(), v);
      const bool numeric = r.ec == std::errc() && r.ptr == cell.data() + cell.size();
      if (numeric && std::isfinite(v)) {
        row.t_s = v;
      } else if (const auto t = parse_utc_datetime_s(cell); !numeric && t) {
        row.t_s = *t;
      } else {
        error_ = where(columns_.time) + ": '" + cell +
                 (numeric ? "' is not a finite number"
                          : "' is neither a number of seconds nor a date-time YYYY-MM-DD HH:MM:SS");
        return ScadaReadResult::kError;
      }
      row.time_present = true;
    }
    for (std::size_t f = 0; f < kScadaQuantityCount; ++f) {
      row.value[f] = std::numeric_limits<double>::quiet_NaN();
      row.present[f] = false;
      if (index_[f] < 0) continue;
      const std::string& cell = fields[static_cast<std::size_t>(index_[f])];
      if (cell.empty()) continue;
      double v = 0.0;
      const auto r = std::from_chars(cell.data(), cell.data() + cell.size(), v);
      const bool numeric = r.ec == std::errc() && r.ptr == cell.data() + cell.size();
      if (!numeric) {
        error_ = where(columns_.quantity[f]) + ": '" + cell + "' is not a number";
        return ScadaReadResult::kError;
      }
      if (!std::isfinite(v)) {
        error_ = where(columns_.quantity[f]) + ": '" + cell + "' is not a finite number";
        return ScadaReadResult::kError;
      }
      row.value[f] = v;
      row.present[f] = true;
    }
    return ScadaReadResult::kRow;
  }
  if (in_->bad()) {
    error_ = path_ + ": read error after line " + std::to_string(line_);
    return ScadaReadResult::kError;
  }
  return ScadaReadResult::kEnd;
}

}  // namespace hal
