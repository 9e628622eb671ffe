#pragma once
// The validation layer for command options: CLI11 validators that every subcommand
// attaches to its numeric and choice options, so a bad value is refused while the
// command line is parsed — before any file is read or written — with the option named
// and what was expected:
//
//   drivetwin: error: --period: -600 is out of range; expected a number > 0 [s]
//
// (CLI11 prefixes the option's name; the exit status is CLI11's, non-zero.) What an
// option's value means for a particular turbine (a rotor speed above its range, a
// sample rate that aliases its mesh lines) needs the drivetrain and is checked by the
// command after loading it, in the same words.
//
// Thread context: command-line parsing (start-up only).

#include <CLI/CLI.hpp>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <limits>
#include <string>

namespace app::cli {

namespace detail {

inline std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return std::string(buf);
}

/// "a number in [lo, hi] [unit]", "a number > lo", ...: what a range expects, in words.
inline std::string describe_range(double lo, double hi, const std::string& unit, bool lo_open,
                                  bool hi_open) {
  std::string expected;
  if (std::isinf(lo) && std::isinf(hi)) {
    expected = "a finite number";
  } else if (std::isinf(hi)) {
    expected = std::string("a number ") + (lo_open ? "> " : ">= ") + format_number(lo);
  } else if (std::isinf(lo)) {
    expected = std::string("a number ") + (hi_open ? "< " : "<= ") + format_number(hi);
  } else {
    expected = std::string("a number in ") + (lo_open ? "(" : "[") + format_number(lo) + ", " +
               format_number(hi) + (hi_open ? ")" : "]");
  }
  if (!unit.empty()) expected += " [" + unit + "]";
  return expected;
}

/// The whole text as a finite double (an optional leading '+'; nothing after the number).
inline bool parse_finite(const std::string& text, double& v) {
  const char* begin = text.data();
  const char* end = text.data() + text.size();
  if (begin != end && *begin == '+') ++begin;
  const auto res = std::from_chars(begin, end, v);
  return res.ec == std::errc() && res.ptr == end && std::isfinite(v);
}

/// "" when `text` is a finite number in the range; else the refusal, ending in `expected`.
inline std::string check_number(const std::string& text, double lo, double hi, bool lo_open,
                                bool hi_open, const std::string& expected) {
  double v = 0.0;
  if (!parse_finite(text, v)) return "'" + text + "' is not a finite number; expected " + expected;
  const bool low = lo_open ? !(v > lo) : !(v >= lo);
  const bool high = hi_open ? !(v < hi) : !(v <= hi);
  if (low || high) return text + " is out of range; expected " + expected;
  return std::string();
}

}  // namespace detail

/// A finite number in a range. `lo_open`/`hi_open`: the bound itself is excluded; an
/// infinite bound is no bound. `unit` is printed after the range ("s", "Hz", "").
/// Refuses non-numbers, trailing text ("12abc"), NaN and ±inf, and values out of range.
inline CLI::Validator number_in(double lo, double hi, const std::string& unit = "",
                                bool lo_open = false, bool hi_open = false) {
  const std::string expected = detail::describe_range(lo, hi, unit, lo_open, hi_open);
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        return detail::check_number(text, lo, hi, lo_open, hi_open, expected);
      },
      expected, "NUMBER");
}

/// A number in [lo, hi], or exactly `special`, which means `special_means` (e.g. 0 for
/// "computed, not overridden"): `--k-h-beta 0` (method C) or 1..10.
inline CLI::Validator number_in_or(double special, const std::string& special_means, double lo,
                                   double hi, const std::string& unit = "") {
  const std::string expected = detail::format_number(special) + " (" + special_means + ") or " +
                               detail::describe_range(lo, hi, unit, false, false);
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        double v = 0.0;
        if (detail::parse_finite(text, v) && v == special) return std::string();
        return detail::check_number(text, lo, hi, false, false, expected);
      },
      expected, "NUMBER");
}

/// A number in a range, or the word `word` (e.g. `run --speed max`).
inline CLI::Validator number_in_or_word(const std::string& word, double lo, double hi,
                                        const std::string& unit = "", bool lo_open = false,
                                        bool hi_open = false) {
  const std::string expected =
      detail::describe_range(lo, hi, unit, lo_open, hi_open) + " or '" + word + "'";
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        if (text == word) return std::string();
        return detail::check_number(text, lo, hi, lo_open, hi_open, expected);
      },
      expected, "NUMBER|" + word);
}

inline constexpr double kInf = std::numeric_limits<double>::infinity();

/// > 0, finite.
inline CLI::Validator positive(const std::string& unit = "") {
  return number_in(0.0, kInf, unit, true);
}
/// ≥ 0, finite.
inline CLI::Validator non_negative(const std::string& unit = "") {
  return number_in(0.0, kInf, unit);
}

/// An integer in [lo, hi].
inline CLI::Validator integer_in(long long lo, long long hi, const std::string& what = "") {
  const std::string expected = "an integer from " + std::to_string(lo) + " to " +
                               std::to_string(hi) + (what.empty() ? "" : " (" + what + ")");
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        long long v = 0;
        const char* begin = text.data();
        const char* end = text.data() + text.size();
        if (begin != end && *begin == '+') ++begin;
        const auto res = std::from_chars(begin, end, v);
        if (res.ec != std::errc() || res.ptr != end)
          return "'" + text + "' is not an integer; expected " + expected;
        if (v < lo || v > hi) return text + " is out of range; expected " + expected;
        return std::string();
      },
      expected, "INT");
}

/// One of the listed words.
inline CLI::Validator one_of(std::initializer_list<const char*> choices) {
  std::string list;
  for (const char* c : choices) list += (list.empty() ? "" : ", ") + std::string(c);
  std::vector<std::string> words(choices.begin(), choices.end());
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        for (const auto& w : words) {
          if (text == w) return std::string();
        }
        return "'" + text + "' is not one of " + list;
      },
      "one of " + list, "WORD");
}

/// A value that `accepts(text, &error)` takes; its refusal is `error` (CLI11 prefixes the
/// option's name). For values a layer of their own parses (month lists, UTC times), so
/// they too are refused while parsing.
template <class Accepts>
CLI::Validator accepted_by(Accepts accepts, const std::string& expected,
                           const std::string& type = "TEXT") {
  return CLI::Validator(
      [accepts](std::string& text) -> std::string {
        std::string error;
        if (accepts(text, &error)) return std::string();
        return error.empty() ? "'" + text + "' is not accepted" : error;
      },
      expected, type);
}

}  // namespace app::cli
