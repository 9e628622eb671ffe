#include "model/drivetrain/effects.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "model/drivetrain/description.hpp"

namespace model {
namespace {

constexpr std::array<EffectKind, kEffectKinds> kKinds{EffectKind::kToothCrack,
                                                      EffectKind::kGearEccentricity,
                                                      EffectKind::kBearingOuterRaceDefect,
                                                      EffectKind::kBearingInnerRaceDefect,
                                                      EffectKind::kBearingBallDefect,
                                                      EffectKind::kShaftUnbalance,
                                                      EffectKind::kShaftMisalignment,
                                                      EffectKind::kPlanetPassModulation,
                                                      EffectKind::kHousingResonance};

constexpr std::array<std::string_view, kEffectKinds> kIds{"tooth_crack",
                                                          "gear_eccentricity",
                                                          "bearing_outer_race_defect",
                                                          "bearing_inner_race_defect",
                                                          "bearing_ball_defect",
                                                          "shaft_unbalance",
                                                          "shaft_misalignment",
                                                          "planet_pass_modulation",
                                                          "housing_resonance"};

// Defaults are moderate faults of a 2 MW gearbox; ranges are what a description may state.
constexpr EffectParameter kCrack[] = {
    {"stiffness_loss", "-", 0.2, 0.0, 0.9, true},
    {"tooth_angle_deg", "deg", 0.0, -360.0, 360.0, false},
};
constexpr EffectParameter kEccentricity[] = {
    {"eccentricity_um", "um", 20.0, 0.0, 1000.0, true},
    {"phase_deg", "deg", 0.0, -360.0, 360.0, false},
};
constexpr EffectParameter kBearingDefect[] = {
    {"impact_force_n", "N", 500.0, 0.0, 1.0e6, true},
    {"slip", "-", 0.01, 0.0, 0.05, true},
    {"defect_width_mm", "mm", 2.0, 0.1, 20.0, false},
};
constexpr EffectParameter kUnbalance[] = {
    {"unbalance_kg_m", "kg*m", 0.005, 0.0, 10.0, true},
    {"phase_deg", "deg", 0.0, -360.0, 360.0, false},
};
constexpr EffectParameter kMisalignment[] = {
    {"misalignment_mrad", "mrad", 2.0, 0.0, 50.0, true},
    {"ratio_1x", "-", 0.5, 0.0, 5.0, true},
    {"direction_deg", "deg", 90.0, -360.0, 360.0, false},
};
constexpr EffectParameter kPlanetPass[] = {
    {"path_stiffness_mn_m", "MN/m", 100.0, 0.0, 1.0e4, true},
    {"window_deg", "deg", 60.0, 5.0, 180.0, true},
};
constexpr EffectParameter kHousing[] = {
    {"frequency_hz", "Hz", 1500.0, 20.0, 20000.0, true},
    {"damping_ratio", "-", 0.02, 0.001, 0.5, true},
    {"mass_kg", "kg", 20.0, 0.1, 1000.0, false},
};

std::size_t index_of(EffectKind kind) {
  return static_cast<std::size_t>(std::find(kKinds.begin(), kKinds.end(), kind) - kKinds.begin());
}

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

std::string_view effect_id(EffectKind kind) { return kIds[index_of(kind)]; }

std::optional<EffectKind> effect_kind(std::string_view id) {
  for (std::size_t i = 0; i < kIds.size(); ++i) {
    if (kIds[i] == id) return kKinds[i];
  }
  return std::nullopt;
}

std::span<const EffectKind> effect_kinds() { return kKinds; }

std::span<const EffectParameter> effect_parameters(EffectKind kind) {
  switch (kind) {
    case EffectKind::kToothCrack:
      return kCrack;
    case EffectKind::kGearEccentricity:
      return kEccentricity;
    case EffectKind::kBearingOuterRaceDefect:
    case EffectKind::kBearingInnerRaceDefect:
    case EffectKind::kBearingBallDefect:
      return kBearingDefect;
    case EffectKind::kShaftUnbalance:
      return kUnbalance;
    case EffectKind::kShaftMisalignment:
      return kMisalignment;
    case EffectKind::kPlanetPassModulation:
      return kPlanetPass;
    case EffectKind::kHousingResonance:
      return kHousing;
  }
  return {};
}

std::optional<double> Effect::parameter(std::string_view name) const {
  const auto params = effect_parameters(kind);
  for (std::size_t i = 0; i < params.size(); ++i) {
    if (name == params[i].name) return parameters[i];
  }
  return std::nullopt;
}

bool Effect::set_parameter(std::string_view name, double value) {
  const auto params = effect_parameters(kind);
  for (std::size_t i = 0; i < params.size(); ++i) {
    if (name == params[i].name) {
      parameters[i] = value;
      return true;
    }
  }
  return false;
}

Effect make_effect(EffectKind kind, std::string location) {
  Effect e;
  e.kind = kind;
  e.location = std::move(location);
  const auto params = effect_parameters(kind);
  for (std::size_t i = 0; i < params.size(); ++i) e.parameters[i] = params[i].default_value;
  return e;
}

std::vector<std::string> effect_locations(const Drivetrain& d, EffectKind kind) {
  std::vector<std::string> out;
  const GearStage* planetary = nullptr;
  for (const GearStage& s : d.stages) {
    if (s.type == StageType::kPlanetary && planetary == nullptr) planetary = &s;
  }
  const int planets = planetary ? planetary->planets : 0;
  auto add_parallel_gears = [&] {
    for (const GearStage& s : d.stages) {
      if (s.type == StageType::kParallel) out.insert(out.end(), s.gears.begin(), s.gears.end());
    }
  };
  auto add_planets = [&](const char* prefix) {
    for (int n = 1; n <= planets; ++n) out.push_back(prefix + std::to_string(n));
  };
  switch (kind) {
    case EffectKind::kToothCrack:
      if (planetary && planetary->gears.size() == 3) {
        out.push_back(planetary->gears[0]);  // sun
        out.push_back(planetary->gears[1]);  // "planet": the first planet
        add_planets(planetary->gears[1].c_str());
      }
      add_parallel_gears();
      break;
    case EffectKind::kGearEccentricity:
      if (planetary && !planetary->gears.empty()) out.push_back(planetary->gears[0]);
      add_parallel_gears();
      break;
    case EffectKind::kBearingOuterRaceDefect:
    case EffectKind::kBearingInnerRaceDefect:
    case EffectKind::kBearingBallDefect:
      for (const Bearing& b : d.bearings) {
        if (b.shaft == "planet") {
          out.push_back(b.id);  // the first planet's bearing
          add_planets(b.id.c_str());
        } else {
          out.push_back(b.id);
        }
      }
      break;
    case EffectKind::kShaftUnbalance:
      for (const GearStage& s : d.stages) out.push_back(s.output_shaft);
      break;
    case EffectKind::kShaftMisalignment:
      for (const GearStage& s : d.stages) {
        if (s.type == StageType::kParallel) out.push_back(s.output_shaft);
      }
      break;
    case EffectKind::kPlanetPassModulation:
      if (planetary && planetary->gears.size() == 3) out.push_back(planetary->gears[2]);  // ring
      break;
    case EffectKind::kHousingResonance:
      for (const MeasurementPoint& mp : d.measurement_points) out.push_back(mp.location);
      break;
  }
  return out;
}

bool check_effect(const Drivetrain& d, const Effect& e, std::string* error) {
  const std::string what =
      "effect '" + std::string(effect_id(e.kind)) + "' at '" + e.location + "'";
  const std::vector<std::string> locations = effect_locations(d, e.kind);
  if (std::find(locations.begin(), locations.end(), e.location) == locations.end()) {
    if (error) {
      std::string list;
      for (const auto& l : locations) list += (list.empty() ? "" : ", ") + l;
      *error = what + ": location: expected one of " +
               (list.empty() ? "(none in this drivetrain)" : list);
    }
    return false;
  }
  const auto params = effect_parameters(e.kind);
  for (std::size_t i = 0; i < params.size(); ++i) {
    const double v = e.parameters[i];
    if (!std::isfinite(v) || v < params[i].lower || v > params[i].upper) {
      if (error) {
        *error = what + ": " + params[i].name + " = " + fmt(v) + ": expected a value in [" +
                 fmt(params[i].lower) + ", " + fmt(params[i].upper) + "] " + params[i].unit;
      }
      return false;
    }
  }
  return true;
}

}  // namespace model
