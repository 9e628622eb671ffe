// `drivetwin drivetrain [--drivetrain NAME|FILE]`: prints the complete description
// (every key, base merged) in the file format of app/config/README.md — the
// starting point for a new turbine's file, and a check of what a file resolves to.
#include <cstdio>
#include <memory>
#include <string>

#include "cli/command.hpp"
#include "config/drivetrain_file.hpp"

namespace {

void setup_drivetrain(CLI::App& sub) {
  auto name = std::make_shared<std::string>();
  app::config::add_drivetrain_option(sub, *name);
  sub.callback([name] {
    const model::Drivetrain d = app::config::load_drivetrain(*name);
    std::fputs(app::config::to_toml(d).c_str(), stdout);
  });
}

const bool kDrivetrainRegistered = app::cli::register_command(
    {"drivetrain", "Print a drivetrain description (built-in or file) as a complete TOML file",
     &setup_drivetrain});

}  // namespace
