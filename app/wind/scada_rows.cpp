#include "wind/scada_rows.hpp"

#include <stdexcept>
#include <string_view>

namespace app::wind {

using hal::ScadaQuantity;

std::string where(const hal::ScadaCsvReader& reader, const hal::ScadaRow& row,
                  const std::string& column, const std::string& key) {
  return reader.path() + ": row " + std::to_string(row.row) + " (line " + std::to_string(row.line) +
         "), column '" + column + "' (" + key + ")";
}

void RowRejections::note(std::size_t row, std::string field, std::string message) {
  if (issues.size() < kMaxScadaIssues)
    issues.push_back({row, std::move(field), std::move(message)});
}

void RowRejections::unreadable(const hal::ScadaCsvReader& reader, std::size_t row) {
  const std::string& msg = reader.error();
  if (msg.find("read error") != std::string::npos) throw std::runtime_error(msg);
  ++rows_rejected;
  ++rejected_nonnumeric;
  // The reader's message names the column: "..., column '<name>': ...".
  std::string field;
  if (const auto at = msg.find("column '"); at != std::string::npos) {
    const auto end_quote = msg.find('\'', at + 8);
    if (end_quote != std::string::npos) field = msg.substr(at + 8, end_quote - at - 8);
  }
  note(row, field, msg + "; row skipped");
}

bool RowRejections::plausible(const ScadaLimits& limits, const hal::ScadaCsvReader& reader,
                              const hal::ScadaRow& row, bool ignore_rotor_speed) {
  for (std::size_t i = 0; i < hal::kScadaQuantityCount; ++i) {
    const auto q = static_cast<ScadaQuantity>(i);
    if (!row.has(q)) continue;
    if (q == ScadaQuantity::kRotorSpeed && ignore_rotor_speed) continue;
    if (const std::string why = limits.why_implausible(q, row.get(q)); !why.empty()) {
      ++rows_rejected;
      ++(q == ScadaQuantity::kRotorSpeed  ? rejected_speed
         : q == ScadaQuantity::kWindSpeed ? rejected_wind
                                          : rejected_range);
      const std::string key(hal::scada_quantity_key(q));
      note(row.row, key,
           where(reader, row, reader.column_name(q), key) + ": " + why + "; row skipped");
      return false;
    }
  }
  return true;
}

void RowRejections::bad_time(const hal::ScadaCsvReader& reader, const hal::ScadaRow& row,
                             const std::string& what) {
  ++rows_rejected;
  ++rejected_time;
  const std::string key(hal::kScadaTimeKey);
  note(row.row, key,
       where(reader, row, reader.time_column_name(), key) + ": " + what + "; row skipped");
}

std::string RowRejections::summary() const {
  return std::to_string(rows_rejected) + " row" + (rows_rejected == 1 ? "" : "s") +
         " rejected (non-numeric or ragged " + std::to_string(rejected_nonnumeric) + ", time " +
         std::to_string(rejected_time) + ", rotor speed " + std::to_string(rejected_speed) +
         ", wind " + std::to_string(rejected_wind) + ", other out of range " +
         std::to_string(rejected_range) + ")";
}

void RowRejections::print(std::FILE* to, const std::string& prefix) const {
  for (const ScadaIssue& i : issues) std::fprintf(to, "%s%s\n", prefix.c_str(), i.message.c_str());
  if (rows_rejected > issues.size()) {
    std::fprintf(to, "%s... %zu more not listed\n", prefix.c_str(), rows_rejected - issues.size());
  }
  std::fprintf(to, "%s%s: skipped, the result covers the other rows\n", prefix.c_str(),
               summary().c_str());
}

}  // namespace app::wind
