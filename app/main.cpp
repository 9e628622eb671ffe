// drivetwin: composition root. Parses the command line and hands over to the
// subcommand; every error reaches the user as one line and a non-zero exit.
#include "cli/command.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
  CLI::App cli{"drivetwin — digital twin of a wind-turbine drivetrain"};
  cli.set_version_flag("--version", DRIVETWIN_VERSION);
  cli.require_subcommand(1);
  for (const auto& command : app::cli::commands()) {
    CLI::App* sub = cli.add_subcommand(command.name, command.description);
    command.setup(*sub);
  }
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return cli.exit(e);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "drivetwin: error: %s\n", e.what());
    return 1;
  }
  return app::cli::exit_status();
}
