#pragma once
// One way for the app tests to run a drivetwin command line: in-process through
// app::cli::run(), exactly as main() does, with what the command printed captured.
//
//   const test_support::CommandResult r = test_support::run_command({"damage", csv, "--period",
//   "-600"}); EXPECT_EQ(r.exit_code, 1) << r.error;
//
// stdout and stderr are both captured (a command-line error is printed by CLI11 to
// stderr, notes and progress go there too), so a test can check what the user saw
// and the test log stays readable. The captures are gtest's: a test that uses this
// must not hold a CaptureStdout/CaptureStderr of its own around the call.

#include <gtest/gtest.h>

#include <ostream>
#include <string>
#include <vector>

#include "cli/run.hpp"

namespace test_support {

/// What one command line ended with, and what it printed.
struct CommandResult {
  int exit_code = 0;
  std::string error;     // what main() prints after "drivetwin: error: " ("" when none)
  bool printed = false;  // the parser printed `error` itself (a command-line error)
  std::string out;       // stdout
  std::string err;       // stderr
};

/// Runs `args` (argv without the program name) as `drivetwin args...` would.
inline CommandResult run_command(const std::vector<std::string>& args) {
  testing::internal::CaptureStdout();
  testing::internal::CaptureStderr();
  const app::cli::RunResult r = app::cli::run(args);
  CommandResult result;
  result.err = testing::internal::GetCapturedStderr();
  result.out = testing::internal::GetCapturedStdout();
  result.exit_code = r.exit_code;
  result.error = r.error;
  result.printed = r.printed;
  return result;
}

/// The command line as one string, for failure messages.
inline std::string joined(const std::vector<std::string>& args) {
  std::string s = "drivetwin";
  for (const auto& a : args) s += " " + a;
  return s;
}

inline std::ostream& operator<<(std::ostream& os, const CommandResult& r) {
  return os << "exit " << r.exit_code << ", error: " << r.error << "\nstderr: " << r.err;
}

}  // namespace test_support
