#include "model/diagnosis/effect_model.hpp"

#include <cmath>

#include "model/dynamics/simulate.hpp"

namespace model::diagnosis {

struct RomEffectSimulator::State {
  dynamics::SimulationOutputs outputs;
};

RomEffectSimulator::RomEffectSimulator(const Drivetrain& drivetrain, double settle_s)
    : drivetrain_(drivetrain), settle_s_(settle_s), state_(std::make_unique<State>()) {}

RomEffectSimulator::~RomEffectSimulator() = default;

std::vector<EffectParameter> RomEffectSimulator::parameters(const Hypothesis&) const {
  // No effect term of the contract is in model/dynamics yet: nothing can be switched on.
  return {};
}

bool RomEffectSimulator::simulate(
    const DynamicsParameters& params, const std::vector<EffectSetting>& effects,
    const calibration::OperatingPoint& op, double sample_rate_hz, double duration_s,
    std::array<calibration::WaveformView, calibration::kMeasurementPoints>& out) {
  if (!effects.empty()) {
    error_ = "the dynamics model has no switchable term for " +
             std::string(effect_id(effects.front().hypothesis->effect));
    return false;
  }
  drivetrain_.dynamics = params;
  dynamics::SimulationSettings settings;
  settings.seconds = settle_s_ + duration_s;
  settings.sample_rate_hz = sample_rate_hz;
  const dynamics::OperatingPoint dop{op.rotor_speed_rpm, op.input_torque_nm};
  if (!dynamics::simulate_rom(drivetrain_, dop, settings, state_->outputs, &error_)) return false;
  const auto skip = static_cast<std::size_t>(std::llround(settle_s_ * sample_rate_hz));
  for (std::size_t p = 0; p < calibration::kMeasurementPoints; ++p) {
    const std::string channel = p < drivetrain_.measurement_points.size()
                                    ? drivetrain_.measurement_points[p].channel
                                    : std::string();
    const auto& ch = state_->outputs.sensor_channels;
    std::size_t idx = ch.size();
    for (std::size_t c = 0; c < ch.size(); ++c)
      if (ch[c] == channel) idx = c;
    if (idx == ch.size() || state_->outputs.acceleration_m_s2[idx].size() <= skip) {
      error_ = "dynamics model output has no usable channel '" + channel + "'";
      return false;
    }
    const std::vector<double>& a = state_->outputs.acceleration_m_s2[idx];
    for (double v : a) {
      if (!std::isfinite(v)) {
        error_ = "dynamics model diverged (non-finite acceleration at '" + channel + "')";
        return false;
      }
    }
    out[p] = {a.data() + skip, a.size() - skip, sample_rate_hz};
  }
  return true;
}

}  // namespace model::diagnosis
