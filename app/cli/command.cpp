#include "cli/command.hpp"

#include <algorithm>
#include <cstring>

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

}  // namespace app::cli
