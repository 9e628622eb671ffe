// `drivetwin demo`: the main job on built-in data, stage by stage (app/demo/demo.hpp).
#include <cstdio>
#include <memory>
#include <string>

#include "cli/command.hpp"
#include "demo/demo.hpp"

namespace {

void setup_demo(CLI::App& sub) {
  auto only = std::make_shared<std::string>();
  sub.add_option("--stage", *only, "Run only the stage of this name");
  sub.callback([only] {
    const app::demo::DemoContext context{stdout};
    std::size_t ran = 0;
    for (const auto& stage : app::demo::stages()) {
      if (!only->empty() && *only != stage.name) continue;
      std::printf("== %s ==\n", stage.name);
      stage.run(context);
      std::printf("\n");
      ++ran;
    }
    if (ran == 0) throw app::cli::CommandError("demo: no stage named '" + *only + "'");
  });
}

const bool kDemoRegistered = app::cli::register_command(
    {"demo", "Run the twin on built-in real data and print a summary of each stage", &setup_demo});

}  // namespace
