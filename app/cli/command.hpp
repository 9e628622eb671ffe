#pragma once
// Subcommands of the drivetwin executable register themselves here, one file
// each in app/cli/, so that adding a command never edits main.cpp:
//
//   namespace {
//   void setup_torque(CLI::App& sub) { ... }
//   const bool kTorqueRegistered = app::cli::register_command(
//       {"torque", "Estimate rotor input torque from SCADA wind speed", &setup_torque});
//   }
//
// The files of app/cli/ are compiled as one translation unit (app/CMakeLists.txt:
// CLI11 is compiled once), so their file-scope names must differ from file to
// file, anonymous namespace or not: suffix them with the command's name.
//
// setup_<name>() adds the subcommand's options to `sub` and sets its callback. A
// callback reports failure by throwing app::cli::CommandError (or any
// std::exception) with a message that names the file, row and field; main()
// prints it and exits non-zero. Start-up / host code only: not real-time.

#include <CLI/CLI.hpp>

#include <vector>

#include "cli/run.hpp"

namespace app::cli {

struct Command {
  const char* name;
  const char* description;
  void (*setup)(CLI::App& sub);
};

/// Adds a command to the registry; called from static initialisers.
bool register_command(const Command& command);

/// The registered commands, sorted by name.
const std::vector<Command>& commands();

}  // namespace app::cli
