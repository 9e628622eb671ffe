// drivetwin: composition root. Hands the command line to the registered
// subcommand (app/cli/run.hpp); every error reaches the user as one line and a
// non-zero exit.
#include <cstdio>
#include <string>
#include <vector>

#include "cli/run.hpp"

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + (argc > 0 ? 1 : 0), argv + argc);
  const app::cli::RunResult result = app::cli::run(args);
  // Command-line errors were printed by the parser; a failing command's message is ours to print.
  if (result.exit_code != 0 && !result.error.empty() && !result.printed)
    std::fprintf(stderr, "drivetwin: error: %s\n", result.error.c_str());
  return result.exit_code;
}
