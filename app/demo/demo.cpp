#include "demo/demo.hpp"

#include <algorithm>

namespace app::demo {
namespace {
std::vector<DemoStage>& registry() {
  static std::vector<DemoStage> list;
  return list;
}
}  // namespace

bool register_stage(const DemoStage& stage) {
  auto& list = registry();
  list.push_back(stage);
  std::stable_sort(list.begin(), list.end(),
                   [](const DemoStage& a, const DemoStage& b) { return a.order < b.order; });
  return true;
}

const std::vector<DemoStage>& stages() { return registry(); }

}  // namespace app::demo
