#include "cli/command.hpp"

#include <algorithm>
#include <cstring>
#include <exception>

#include "config/drivetrain_file.hpp"

namespace app::cli {
namespace {
std::vector<Command>& registry() {
  static std::vector<Command> commands;
  return commands;
}
}  // namespace

bool register_command(const Command& command) {
  auto& list = registry();
  list.push_back(command);
  std::sort(list.begin(), list.end(),
            [](const Command& a, const Command& b) { return std::strcmp(a.name, b.name) < 0; });
  return true;
}

const std::vector<Command>& commands() { return registry(); }

int& exit_status() {
  static int status = 0;
  return status;
}

RunResult run(const std::vector<std::string>& args) {
  RunResult result;
  try {
    // Named here: parse(vector) never sees argv[0], and help says "Usage: drivetwin ...".
    CLI::App cli{"drivetwin — digital twin of a wind-turbine drivetrain", "drivetwin"};
    cli.set_version_flag("--version", DRIVETWIN_VERSION);
    cli.require_subcommand(1);
    for (const auto& command : commands()) {
      command.setup(*cli.add_subcommand(command.name, command.description));
    }
    exit_status() = 0;
    // CLI11 would only say "A subcommand is required": name what was given instead.
    if (!args.empty() && !args.front().empty() && args.front()[0] != '-') {
      const auto& list = commands();
      const bool known = std::any_of(list.begin(), list.end(),
                                     [&](const Command& c) { return args.front() == c.name; });
      if (!known) {
        result.exit_code = 2;
        result.error = "unknown command '" + args.front() + "' (commands:";
        for (const auto& c : list) result.error += std::string(" ") + c.name;
        result.error += "; drivetwin --help describes them)";
        return result;
      }
    }
    // CLI11 parses a vector in reverse order (it pops from the back).
    std::vector<std::string> reversed(args.rbegin(), args.rend());
    try {
      cli.parse(reversed);
      result.exit_code = exit_status();
    } catch (const CLI::ParseError& e) {
      result.exit_code = cli.exit(e);  // prints help/version to stdout, errors to stderr
      if (result.exit_code != 0) {
        result.error = e.what();
        result.printed = true;
      }
    }
  } catch (const std::exception& e) {
    result.exit_code = 1;
    result.error = e.what();
  }
  return result;
}

}  // namespace app::cli

namespace app::config {

CLI::Option* add_drivetrain_option(CLI::App& sub, std::string& value) {
  value = kDefaultDrivetrain;
  return sub
      .add_option("--drivetrain", value,
                  "Drivetrain description: a built-in name (paper-2mw, kelmarsh-mm92) or a "
                  "TOML file (app/config/README.md)")
      ->capture_default_str();
}

}  // namespace app::config
