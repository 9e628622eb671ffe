#pragma once
// The command line as a function, without CLI11 in the interface: main() and the
// app tests call run(); only the subcommand files (app/cli/*.cpp, through
// command.hpp) see CLI11. Including CLI11 costs every translation unit a
// megabyte of object code (its header-defined validators and inline virtual
// classes), so headers that do not register options stay clear of it.
//
// Thread context: start-up / command code only (allocates, throws inside).

#include <stdexcept>
#include <string>
#include <vector>

namespace app::cli {

/// An error the user caused (bad file, bad value): printed without a stack of context.
class CommandError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Exit status a command's callback sets (default 0); run() returns it.
int& exit_status();

/// What one command line ended with.
struct RunResult {
  int exit_code = 0;
  std::string error;     // what main() prints after "drivetwin: error: " ("" when none)
  bool printed = false;  // the parser has printed it already (a command-line error)
};

/// Parses `args` (argv without the program name) against every registered
/// subcommand and runs the chosen one, as the executable does. Help and version
/// text go to stdout and give exit code 0; a command-line error is printed by
/// CLI11 to stderr and returned with its exit code; an exception thrown by a
/// command (CommandError or any std::exception) is returned with exit code 1 and
/// its message, not printed. Never throws.
RunResult run(const std::vector<std::string>& args);

}  // namespace app::cli
