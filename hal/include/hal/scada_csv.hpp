#pragma once
// Streaming reader for SCADA CSV files: the `scada.csv` of a recording bundle
// (shared/reference/recording-bundle.md: `t_s,wind_speed_mps,rotor_speed_rpm,
// power_kw,pitch_deg,torque_nm`) and other SCADA exports through a column
// mapping (e.g. the Kelmarsh wind farm's `Date and time`, `Wind speed (m/s)`,
// `Rotor speed (RPM)`, `Power (kW)`, `Pitch angle (°)`; UTF-8 header).
//
// Rows are read one at a time, so years of 10-minute or 1-second data stream
// through constant memory. Values are parsed with std::from_chars (no locale).
// Every failure names the file, the data row (1 = first row after the header),
// the line, the column and what was expected. Plausibility that depends on the
// turbine (negative wind speed, rotor speed out of range) is the caller's job.
//
// Cells: an empty cell is "absent" (present[f] == false, value NaN) — real
// exports leave gaps; text that is not a number, or a non-finite number
// ("nan", "inf"), is an error. Times: a number of seconds, or an ISO-like UTC
// date-time `YYYY-MM-DD HH:MM:SS` / `YYYY-MM-DDTHH:MM:SS[Z]`, converted to
// seconds since 1970-01-01T00:00:00Z.
//
// Thread context: non-real-time (file I/O, allocates per line). One reader
// per thread; no shared state. No exceptions escape.

#include <array>
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

namespace hal {

/// The quantities a SCADA row can carry, in the units of the bundle's scada.csv.
enum class ScadaField : std::uint8_t {
  kTime,                // [s]   t_s (or a date-time, converted)
  kWindSpeed,           // [m/s] wind_speed_mps, hub height / nacelle anemometer
  kRotorSpeed,          // [rpm] rotor_speed_rpm (low-speed shaft)
  kPower,               // [kW]  power_kw, electrical
  kPitch,               // [deg] pitch_deg, blade pitch
  kTorque,              // [N·m] torque_nm, measured rotor torque
  kAmbientTemperature,  // [°C] ambient_temperature_c (drivetwin extension of the bundle)
  kYawError,            // [deg] yaw_error_deg: wind direction − nacelle heading (extension)
};
inline constexpr std::size_t kScadaFieldCount = 8;

/// The bundle's column name of a field ("t_s", "wind_speed_mps", ...).
const char* scada_field_name(ScadaField field);

/// Which column of the file holds each field ("" = not mapped). Time and wind
/// speed must be mapped and present in the header; the rest are optional.
struct ScadaColumns {
  std::array<std::string, kScadaFieldCount> column{};
};

/// The bundle's own header names (recording-bundle.md), plus the two optional
/// extensions ambient_temperature_c and yaw_error_deg.
ScadaColumns bundle_scada_columns();
/// The Kelmarsh wind farm export (Plumley 2022, doi:10.5281/zenodo.5841833).
ScadaColumns kelmarsh_scada_columns();

/// Parses a mapping: a preset name ("bundle", "kelmarsh") or a list
/// `field=Column name;field=Column name...` with field one of the bundle names
/// (t_s, wind_speed_mps, rotor_speed_rpm, power_kw, pitch_deg, torque_nm,
/// ambient_temperature_c, yaw_error_deg);
/// unnamed fields keep the bundle's names. On failure returns nullopt and sets
/// *error to a message naming the offending part.
std::optional<ScadaColumns> parse_scada_columns(std::string_view spec, std::string* error);

/// Seconds since 1970-01-01T00:00:00Z of `YYYY-MM-DD[ T]HH:MM:SS[Z]`, or nullopt.
std::optional<double> parse_utc_datetime_s(std::string_view text);

/// One data row.
struct ScadaRow {
  std::size_t row = 0;                           // data row number, 1 = first row after the header
  std::size_t line = 0;                          // line number in the file, 1 = header
  std::array<double, kScadaFieldCount> value{};  // NaN when absent
  std::array<bool, kScadaFieldCount> present{};  // false: column not mapped or cell empty

  double get(ScadaField f) const { return value[static_cast<std::size_t>(f)]; }
  bool has(ScadaField f) const { return present[static_cast<std::size_t>(f)]; }
};

enum class ScadaReadResult : std::uint8_t { kRow, kEnd, kError };

class ScadaCsvReader {
 public:
  /// Opens the file and reads its header. On failure returns false; error()
  /// names the file and what is missing (e.g. a required column).
  [[nodiscard]] bool open(const std::string& path, const ScadaColumns& columns);

  /// As open(), reading CSV text held in memory (e.g. data compiled into the
  /// binary); `name` stands for the file in messages.
  [[nodiscard]] bool open_text(std::string_view text, const std::string& name,
                               const ScadaColumns& columns);

  /// Reads the next data row into `row`. Blank lines are skipped. Empty cells,
  /// including time and wind speed, come back absent: the caller decides.
  [[nodiscard]] ScadaReadResult next(ScadaRow& row);

  /// The last error: "<file>: row <n> (line <l>), column '<name>': <what>".
  const std::string& error() const { return error_; }
  const std::string& path() const { return path_; }
  /// Whether the header maps the field to a column.
  bool has_column(ScadaField f) const { return index_[static_cast<std::size_t>(f)] >= 0; }
  /// Header name of the column mapped to a field ("" when unmapped).
  const std::string& column_name(ScadaField f) const {
    return columns_.column[static_cast<std::size_t>(f)];
  }

 private:
  [[nodiscard]] bool read_header();

  std::ifstream file_;
  std::istringstream memory_;
  std::istream* in_ = &file_;
  std::string path_;
  ScadaColumns columns_;
  std::array<int, kScadaFieldCount> index_{};
  std::size_t header_fields_ = 0;
  std::size_t line_ = 0;
  std::size_t row_ = 0;
  std::string text_;
  std::vector<std::string> fields_;
  std::string error_;
};

}  // namespace hal
