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

#include "hal/scada_quantity.hpp"

namespace hal {

/// Which column of the file holds the time and each quantity ("" = not mapped). Time and
/// wind speed must be mapped and present in the header; the rest are optional. The
/// quantities are hal::ScadaQuantity, in their fixed units (scada_quantity.hpp).
struct ScadaColumns {
  std::string time = "t_s";
  std::array<std::string, kScadaQuantityCount> quantity{};
};

/// The bundle's name of the time column.
inline constexpr std::string_view kScadaTimeKey = "t_s";

/// The bundle's own header names (recording-bundle.md), plus the optional extensions
/// generator_speed_rpm, ambient_temperature_c and yaw_error_deg: each quantity's key.
ScadaColumns bundle_scada_columns();
/// The Kelmarsh wind farm export (Plumley 2022, doi:10.5281/zenodo.5841833).
ScadaColumns kelmarsh_scada_columns();

/// Parses a mapping: a preset name ("bundle", "kelmarsh") or a list
/// `field=Column name;field=Column name...` with field t_s or a quantity's key
/// (wind_speed_mps, rotor_speed_rpm, generator_speed_rpm, power_kw, pitch_deg, torque_nm,
/// yaw_error_deg, ambient_temperature_c);
/// unnamed fields keep the bundle's names. On failure returns nullopt and sets
/// *error to a message naming the offending part.
std::optional<ScadaColumns> parse_scada_columns(std::string_view spec, std::string* error);

/// Seconds since 1970-01-01T00:00:00Z of `YYYY-MM-DD[ T]HH:MM:SS[Z]`, or nullopt.
std::optional<double> parse_utc_datetime_s(std::string_view text);

/// One data row.
struct ScadaRow {
  std::size_t row = 0;        // data row number, 1 = first row after the header
  std::size_t line = 0;       // line number in the file, 1 = header
  double t_s = 0.0;           // [s] NaN when absent
  bool time_present = false;  // false: cell empty
  std::array<double, kScadaQuantityCount> value{};  // NaN when absent
  std::array<bool, kScadaQuantityCount> present{};  // false: column not mapped or cell empty

  double get(ScadaQuantity q) const { return value[static_cast<std::size_t>(q)]; }
  bool has(ScadaQuantity q) const { return present[static_cast<std::size_t>(q)]; }
  double time_s() const { return t_s; }
  bool has_time() const { return time_present; }
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
  /// Whether the header maps the quantity to a column.
  bool has_column(ScadaQuantity q) const { return index_[static_cast<std::size_t>(q)] >= 0; }
  /// Header name of the column mapped to a quantity ("" when unmapped).
  const std::string& column_name(ScadaQuantity q) const {
    return columns_.quantity[static_cast<std::size_t>(q)];
  }
  /// Header name of the time column.
  const std::string& time_column_name() const { return columns_.time; }

 private:
  [[nodiscard]] bool read_header();

  std::ifstream file_;
  std::istringstream memory_;
  std::istream* in_ = &file_;
  std::string path_;
  ScadaColumns columns_;
  std::array<int, kScadaQuantityCount> index_{};
  int time_index_ = -1;
  std::size_t header_fields_ = 0;
  std::size_t line_ = 0;
  std::size_t row_ = 0;
  std::string text_;
  std::vector<std::string> fields_;
  std::string error_;
};

}  // namespace hal
