// The option tables of tests/app/cli/test_option_validation.cpp (drivetwin's commands) and
// tests/tools/test_tool_options.cpp (the host tools): one numeric option, the values it
// must refuse and the values it must take. Both check the same layer (app/cli/options.hpp),
// so both feed it the same values no number may take.
#pragma once

#include <string>
#include <vector>

namespace test_support {

// No numeric option may take these: NaN, ±inf, an overflow, text, trailing text, hex, an
// empty value, a leading blank.
inline const std::vector<std::string> kNeverANumber{"nan", "NaN",   "inf",  "-inf", "1e999",
                                                    "abc", "12abc", "0x10", "",     " 5"};
// Nor an integer option these.
inline const std::vector<std::string> kNeverAnInteger{"1.5", "1e3", "3x"};

struct NumericOption {
  std::string name;                       // "--period"
  std::vector<std::string> out_of_range;  // refused by its range
  std::vector<std::string> valid;         // taken by the parser
  bool integer = false;
};

/// Every value `o` must refuse: those no number may take, its own out-of-range values, and,
/// for an integer option, those no integer may take.
inline std::vector<std::string> refused_values(const NumericOption& o) {
  std::vector<std::string> bad = kNeverANumber;
  bad.insert(bad.end(), o.out_of_range.begin(), o.out_of_range.end());
  if (o.integer) bad.insert(bad.end(), kNeverAnInteger.begin(), kNeverAnInteger.end());
  return bad;
}

}  // namespace test_support
