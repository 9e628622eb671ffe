#pragma once
// Unit factors of the ISO 6336 / ISO 281 formulas, which take millimetres.
// One definition for the files of this library's unity TU (docs/ci.md).
#include <numbers>

namespace model::fatigue {

inline constexpr double kMm = 1e3;  // [mm/m]

}  // namespace model::fatigue
