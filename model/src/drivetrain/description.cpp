#include "model/drivetrain/description.hpp"

#include <algorithm>

namespace model {
namespace {
template <typename T>
const T* find_by_id(const std::vector<T>& items, std::string_view id) {
  auto it = std::find_if(items.begin(), items.end(), [&](const T& x) { return x.id == id; });
  return it == items.end() ? nullptr : &*it;
}
}  // namespace

const Gear* Drivetrain::gear(std::string_view id) const { return find_by_id(gears, id); }
const Bearing* Drivetrain::bearing(std::string_view id) const { return find_by_id(bearings, id); }
const Shaft* Drivetrain::shaft(std::string_view id) const { return find_by_id(shafts, id); }
const Material* Drivetrain::material(std::string_view id) const {
  return find_by_id(materials, id);
}
const GearStage* Drivetrain::stage(std::string_view id) const { return find_by_id(stages, id); }

std::vector<std::string> builtin_drivetrain_names() { return {"paper-2mw"}; }

std::optional<Drivetrain> builtin_drivetrain(std::string_view name) {
  if (name == "paper-2mw") return paper_2mw();
  return std::nullopt;
}

}  // namespace model
