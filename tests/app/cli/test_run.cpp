// app::cli::run(): the command line as main() sees it, without CLI11 in the caller.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "cli/run.hpp"
#include "support/run_command.hpp"

namespace {

TEST(CliRun, ListsEveryRegisteredCommandInItsHelpAndExitsZero) {
  // Act
  const test_support::CommandResult r = test_support::run_command({"--help"});
  const std::string& out = r.out;

  // Assert: help is not an error; the commands README.md lists are all there.
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_TRUE(r.error.empty()) << r.error;
  EXPECT_NE(out.find("Usage: drivetwin "), std::string::npos) << out;
  for (const char* name : {"torque", "simulate", "damage", "calibrate", "demo", "drivetrain"})
    EXPECT_NE(out.find(name), std::string::npos) << name << " missing from:\n" << out;
}

TEST(CliRun, RefusesAnUnknownSubcommandNamingIt) {
  // Act
  const test_support::CommandResult r =
      test_support::run_command({"no-such-command", "--rpm", "3"});

  // Assert: the message names what was typed and what exists.
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_FALSE(r.printed);
  EXPECT_NE(r.error.find("'no-such-command'"), std::string::npos) << r.error;
  EXPECT_NE(r.error.find("simulate"), std::string::npos) << r.error;
}

TEST(CliRun, RequiresASubcommand) {
  // Act
  const test_support::CommandResult r = test_support::run_command({});

  // Assert
  EXPECT_NE(r.exit_code, 0);
  EXPECT_FALSE(r.error.empty());
}

TEST(CliRun, ReturnsACommandsErrorWithExitCodeOneWithoutPrintingIt) {
  // Act: the torque command throws on a file that is not there.
  const test_support::CommandResult r =
      test_support::run_command({"torque", "no-such-scada-file.csv"});

  // Assert: main() prints it (once), so run() leaves it unprinted.
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_FALSE(r.printed);
  EXPECT_NE(r.error.find("no-such-scada-file.csv"), std::string::npos) << r.error;
}

TEST(CliRun, ResetsTheExitStatusOfAPreviousCommand) {
  // Arrange: a previous command left a failure status behind.
  app::cli::exit_status() = 2;

  // Act
  const test_support::CommandResult r = test_support::run_command({"drivetrain", "--help"});

  // Assert
  EXPECT_EQ(r.exit_code, 0) << r.error;
}

}  // namespace
