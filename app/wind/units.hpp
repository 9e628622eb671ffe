#pragma once
// SCADA units (rpm, degrees) to the model's (rad/s, rad).
// One definition for the files of this library's unity TU (docs/ci.md).
#include <numbers>

namespace app::wind {

inline constexpr double kRpmToRadS = 2.0 * std::numbers::pi / 60.0;
inline constexpr double kDegToRad = std::numbers::pi / 180.0;

}  // namespace app::wind
