#pragma once
// The description gives angles in degrees, the model takes radians.
// One definition for the files of this library's unity TU (docs/ci.md).
#include <numbers>

namespace app::config {

inline constexpr double kDeg = std::numbers::pi / 180.0;  // [rad/°]

}  // namespace app::config
