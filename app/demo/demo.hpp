#pragma once
// `drivetwin demo` runs a list of stages on built-in data and prints a readable
// summary of each. A stage registers itself from its own file (like the CLI
// commands), so adding one never edits the demo command:
//
//   namespace {
//   void run_my_stage(const app::demo::DemoContext& ctx) { std::fprintf(ctx.out, ...); }
//   const bool kRegistered = app::demo::register_stage({20, "gearbox", &run_my_stage});
//   }
//
// Stages run in ascending `order` (wind load = 10; leave gaps). A stage reports
// failure by throwing (app::cli::CommandError); the demo stops with a non-zero exit.
// Thread context: start-up / command code only.

#include <cstdio>
#include <vector>

namespace app::demo {

struct DemoContext {
  std::FILE* out;  // where the summary goes
};

struct DemoStage {
  int order;
  const char* name;
  void (*run)(const DemoContext& context);
};

bool register_stage(const DemoStage& stage);

/// Registered stages, sorted by order.
const std::vector<DemoStage>& stages();

}  // namespace app::demo
