#include "model/drivetrain/kinematics.hpp"

#include <cassert>
#include <cmath>

namespace model {

BearingFrequencies bearing_orders(const Bearing& b) {
  const double ratio = b.element_diameter_m / b.pitch_diameter_m * std::cos(b.contact_angle_rad);
  BearingFrequencies o;
  o.shaft_hz = 1.0;
  o.bpfo_hz = 0.5 * b.elements * (1.0 - ratio);
  o.bpfi_hz = 0.5 * b.elements * (1.0 + ratio);
  o.bsf_hz = b.pitch_diameter_m / (2.0 * b.element_diameter_m) * (1.0 - ratio * ratio);
  o.ftf_hz = 0.5 * (1.0 - ratio);
  return o;
}

Kinematics::Kinematics(const Drivetrain& drivetrain) : drivetrain_(&drivetrain) {
  double speed = 1.0;  // input speed of the current stage, relative to the rotor
  for (const GearStage& stage : drivetrain.stages) {
    if (stage_count_ == kMaxStages) break;
    const std::size_t i = stage_count_++;
    input_ratio_[i] = speed;
    if (stage.type == StageType::kPlanetary) {
      // Carrier in, ring fixed, sun out (Willis): n_sun / n_carrier = 1 + z_ring / z_sun.
      const Gear* sun = drivetrain.gear(stage.gears.at(0));
      const Gear* planet = drivetrain.gear(stage.gears.at(1));
      const Gear* ring = drivetrain.gear(stage.gears.at(2));
      assert(sun && planet && ring);
      stage_ratio_[i] = 1.0 + static_cast<double>(ring->teeth) / sun->teeth;
      mesh_order_[i] = speed * ring->teeth;  // ring fixed: f_mesh = z_ring · f_carrier
      planets_[i] = stage.planets;
      // Planet relative to the carrier: ω_p,rel = ω_c · z_ring / z_planet.
      planet_ratio_ = speed * static_cast<double>(ring->teeth) / planet->teeth;
    } else {
      const Gear* wheel = drivetrain.gear(stage.gears.at(0));
      const Gear* pinion = drivetrain.gear(stage.gears.at(1));
      assert(wheel && pinion);
      stage_ratio_[i] = static_cast<double>(wheel->teeth) / pinion->teeth;
      mesh_order_[i] = speed * wheel->teeth;
    }
    speed *= stage_ratio_[i];
  }
  overall_ratio_ = speed;
}

double Kinematics::stage_input_hz(std::size_t stage, double rotor_rpm) const {
  return rotor_rpm / 60.0 * input_ratio_[stage];
}

double Kinematics::mesh_hz(std::size_t stage, double rotor_rpm) const {
  return rotor_rpm / 60.0 * mesh_order_[stage];
}

double Kinematics::planet_pass_hz(std::size_t stage, double rotor_rpm) const {
  return planets_[stage] * stage_input_hz(stage, rotor_rpm);
}

std::optional<double> Kinematics::shaft_hz(std::string_view shaft, double rotor_rpm) const {
  const double rotor_hz = rotor_rpm / 60.0;
  if (shaft == "planet") return rotor_hz * planet_ratio_;
  for (std::size_t i = 0; i < stage_count_; ++i) {
    const GearStage& stage = drivetrain_->stages[i];
    if (stage.input_shaft == shaft) return rotor_hz * input_ratio_[i];
    if (stage.output_shaft == shaft) return rotor_hz * input_ratio_[i] * stage_ratio_[i];
  }
  if (stage_count_ == 0 && !drivetrain_->shafts.empty() &&
      drivetrain_->shafts.front().id == shaft) {
    return rotor_hz;  // a single-shaft machine (no gear stage): the shaft is the rotor
  }
  return std::nullopt;
}

std::optional<BearingFrequencies> Kinematics::bearing_hz(std::string_view id,
                                                         double rotor_rpm) const {
  const Bearing* b = drivetrain_->bearing(id);
  if (b == nullptr) return std::nullopt;
  const std::optional<double> fr = shaft_hz(b->shaft, rotor_rpm);
  if (!fr) return std::nullopt;
  BearingFrequencies f = bearing_orders(*b);
  f.shaft_hz *= *fr;
  f.bpfo_hz *= *fr;
  f.bpfi_hz *= *fr;
  f.bsf_hz *= *fr;
  f.ftf_hz *= *fr;
  return f;
}

}  // namespace model
