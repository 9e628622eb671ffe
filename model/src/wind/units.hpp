#pragma once
// Rotor speed: SCADA and the turbine description give rpm, the model works in rad/s.
// One definition for the files of this library's unity TU (docs/ci.md).
#include <numbers>

namespace model::wind {

inline constexpr double kRpmToRadS = 2.0 * std::numbers::pi / 60.0;

}  // namespace model::wind
