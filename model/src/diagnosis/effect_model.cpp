#include "model/diagnosis/effect_model.hpp"

#include <algorithm>
#include <cmath>

#include "model/drivetrain/effects.hpp"
#include "model/dynamics/simulate.hpp"

namespace model::diagnosis {

struct RomEffectSimulator::State {
  dynamics::SimulationOutputs outputs;
};

RomEffectSimulator::RomEffectSimulator(const Drivetrain& drivetrain, double settle_s)
    : drivetrain_(drivetrain), settle_s_(settle_s), state_(std::make_unique<State>()) {}

RomEffectSimulator::~RomEffectSimulator() = default;

namespace {
// The diagnosis's effects are the contract's, in the contract's order, as model::EffectKind.
model::EffectKind kind_of(Effect e) { return static_cast<model::EffectKind>(static_cast<int>(e)); }
static_assert(static_cast<int>(Effect::kHousingResonance) ==
              static_cast<int>(model::EffectKind::kHousingResonance));

// A bearing's slip is not fitted: the recording's own defect rate sets it.
bool set_from_rate(std::string_view name) { return name == "slip"; }
}  // namespace

std::vector<EffectParameter> RomEffectSimulator::parameters(const Hypothesis& h) const {
  std::vector<EffectParameter> out;
  for (const model::EffectParameter& p : model::effect_parameters(kind_of(h.effect))) {
    if (!p.fitted || set_from_rate(p.name)) continue;
    EffectParameter q;
    q.name = p.name;
    q.upper = p.upper;
    q.initial = p.default_value;
    // From the term's default; severities searched as logarithms from 10⁻⁴ of their range up.
    q.log_scale = p.upper > 0.0 && p.lower >= 0.0;
    q.lower = q.log_scale ? std::max(p.lower, 1e-4 * p.upper) : p.lower;
    q.initial = std::clamp(q.initial, q.lower, q.upper);
    out.push_back(q);
  }
  return out;
}

bool RomEffectSimulator::simulate(
    const DynamicsParameters& params, const std::vector<EffectSetting>& effects,
    const calibration::OperatingPoint& op, double sample_rate_hz, double duration_s,
    std::array<calibration::WaveformView, calibration::kMeasurementPoints>& out) {
  drivetrain_.effects.clear();
  for (const EffectSetting& e : effects) {
    const Hypothesis& h = *e.hypothesis;
    model::Effect m = model::make_effect(kind_of(h.effect), h.location);
    std::size_t i = 0;
    for (const model::EffectParameter& p : model::effect_parameters(m.kind)) {
      if (!p.fitted || set_from_rate(p.name)) continue;
      if (i < kMaxEffectParameters) m.set_parameter(p.name, e.values[i++]);
    }
    if (e.measured_rate_order > 0.0 && h.rate_order > 0.0)
      m.set_parameter("slip", std::clamp(1.0 - e.measured_rate_order / h.rate_order, 0.0, 0.05));
    std::string why;
    if (!model::check_effect(drivetrain_, m, &why)) {
      error_ = why;
      return false;
    }
    drivetrain_.effects.push_back(m);
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
