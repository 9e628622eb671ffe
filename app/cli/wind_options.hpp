#pragma once
// Validators for the options of the wind commands (`torque`, `fit-cp`) whose values a
// parser of app/wind reads: month lists and UTC times, refused while the command line
// is parsed (app/cli/options.hpp), before the SCADA file is read.
//
// Thread context: command-line parsing (start-up only).

#include <stdexcept>
#include <string>

#include "cli/options.hpp"
#include "wind/heldout.hpp"
#include "wind/torque_estimate.hpp"

namespace app::cli {

/// "1-3", "12,1,2", "DJF,MAM": app::wind::MonthSet::parse.
inline CLI::Validator month_list() {
  return accepted_by(
      [](const std::string& text, std::string* error) {
        return app::wind::MonthSet::parse(text, error).has_value();
      },
      "months 1..12, ranges a-b or seasons DJF, MAM, JJA, SON", "MONTHS");
}

/// "YYYY-MM-DD[ HH:MM:SS]" UTC or seconds since 1970: app::wind::parse_time_option.
inline CLI::Validator utc_time() {
  return accepted_by(
      [](const std::string& text, std::string* error) {
        try {
          (void)app::wind::parse_time_option("", text);
          return true;
        } catch (const std::exception&) {
          *error = "'" + text +
                   "' is not a time (expected YYYY-MM-DD, YYYY-MM-DD HH:MM:SS or "
                   "seconds since 1970 UTC)";
          return false;
        }
      },
      "YYYY-MM-DD[ HH:MM:SS] UTC or seconds", "TIME");
}

}  // namespace app::cli
