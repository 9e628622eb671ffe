#pragma once
// The one policy for SCADA rows that cannot be used, shared by every command reading a
// SCADA file offline (`damage`, `torque`, `fit-cp`; the real-time loop's supervisor sets
// fault bits instead): a row is rejected — skipped, counted by reason, the first
// kMaxScadaIssues named with file, row, line and column — when
//   - the reader cannot read it (a cell that is not a finite number: NaN, inf, text; a
//     row with too few or too many cells): `nonnumeric`;
//   - one of its values is outside its plausibility limit for the turbine
//     (app/wind/scada_limits.hpp): `speed` (rotor speed), `wind` (wind speed), `range`
//     (any other quantity);
//   - (`damage`, which integrates over time) its t_s is missing or not after the previous
//     accepted row's: `time`.
// One bad row in years of SCADA never stops a command nor touches its result: the command
// finishes on the other rows, prints the count and the named rows on stderr and exits 2
// (app/cli/command.hpp). A file whose every row is rejected is an error (exit 1).
// An I/O error of the reader still stops the command (nothing after it can be trusted).
//
// Thread context: non-real-time command code (allocates for messages).

#include <cstddef>
#include <cstdio>
#include <string>
#include <vector>

#include "hal/scada_csv.hpp"
#include "wind/scada_limits.hpp"

namespace app::wind {

inline constexpr std::size_t kMaxScadaIssues = 50;

/// One rejected row (or a reported gap), as printed and as written into a JSON result.
struct ScadaIssue {
  std::size_t row = 0;  // data row (1 = first after the header)
  std::string field;    // column key, e.g. "t_s", "wind_speed_mps"
  std::string message;  // full text with file, row, line and column
};

/// The rows rejected from one file, by reason. `issues` holds the first kMaxScadaIssues
/// messages (of rejections and of whatever else the reader of the file reports, e.g.
/// gaps).
struct RowRejections {
  std::size_t rows_rejected = 0;
  std::size_t rejected_nonnumeric = 0, rejected_time = 0, rejected_speed = 0, rejected_wind = 0;
  std::size_t rejected_range = 0;  // another quantity outside its plausibility limit
  std::vector<ScadaIssue> issues;

  /// Lists one message (the first kMaxScadaIssues only).
  void note(std::size_t row, std::string field, std::string message);
  /// The row `reader.next()` just refused (data row `row`): counted as non-numeric, its
  /// message (which names the column) listed. Throws std::runtime_error on an I/O error.
  void unreadable(const hal::ScadaCsvReader& reader, std::size_t row);
  /// True when every value of `row` is plausible for the turbine; else the row is counted
  /// by the first implausible quantity and named. `ignore_rotor_speed`: the caller does
  /// not use the measured speed (the controller's steady state replaces it).
  bool plausible(const ScadaLimits& limits, const hal::ScadaCsvReader& reader,
                 const hal::ScadaRow& row, bool ignore_rotor_speed = false);
  /// Counts and names a row whose t_s is missing or not after the previous one's.
  void bad_time(const hal::ScadaCsvReader& reader, const hal::ScadaRow& row,
                const std::string& what);

  /// "<n> rows rejected (non-numeric a, time b, rotor speed c, wind d, other e)".
  std::string summary() const;
  /// Prints the listed messages, one a line prefixed by `prefix` ("drivetwin torque: "),
  /// "... n more" when not all were listed, and the summary.
  void print(std::FILE* to, const std::string& prefix) const;
};

/// "<file>: row R (line L), column 'C' (key)": where a value of a row is.
std::string where(const hal::ScadaCsvReader& reader, const hal::ScadaRow& row,
                  const std::string& column, const std::string& key);

}  // namespace app::wind
