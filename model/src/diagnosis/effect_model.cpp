#include "model/diagnosis/effect_model.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include "model/drivetrain/effects.hpp"
#include "model/dynamics/simulate.hpp"

namespace model::diagnosis {

// One remembered simulation: its inputs and the waveforms it returned.
struct RememberedRun {
  DynamicsParameters params{};
  std::vector<EffectSetting> effects;
  calibration::OperatingPoint op{};
  double sample_rate_hz = 0.0;
  double duration_s = 0.0;
  std::array<std::vector<double>, calibration::kMeasurementPoints> waves;
  std::uint64_t last_use = 0;  // 0: empty
};

struct RomEffectSimulator::State {
  dynamics::SimulationOutputs outputs;
  std::array<RememberedRun, RomEffectSimulator::kRemembered> runs;
  std::uint64_t calls = 0;
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

// Equal bit for bit: the inputs a deterministic simulation cannot tell apart. (−0 and +0,
// or two NaN payloads, compare unequal: a simulation too many, never a wrong answer.)
static_assert(std::is_trivially_copyable_v<DynamicsParameters>);
template <class T>
bool same_bits(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

bool same_inputs(const RememberedRun& r, const DynamicsParameters& params,
                 const std::vector<EffectSetting>& effects, const calibration::OperatingPoint& op,
                 double sample_rate_hz, double duration_s) {
  if (r.last_use == 0 || !same_bits(r.sample_rate_hz, sample_rate_hz) ||
      !same_bits(r.duration_s, duration_s) ||
      !same_bits(r.op.rotor_speed_rpm, op.rotor_speed_rpm) ||
      !same_bits(r.op.input_torque_nm, op.input_torque_nm) || r.effects.size() != effects.size() ||
      !same_bits(r.params, params))
    return false;
  for (std::size_t i = 0; i < effects.size(); ++i) {
    if (r.effects[i].hypothesis != effects[i].hypothesis ||
        !same_bits(r.effects[i].values, effects[i].values) ||
        !same_bits(r.effects[i].measured_rate_order, effects[i].measured_rate_order))
      return false;
  }
  return true;
}
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
  State& st = *state_;
  ++st.calls;
  for (RememberedRun& r : st.runs) {
    if (!same_inputs(r, params, effects, op, sample_rate_hz, duration_s)) continue;
    r.last_use = st.calls;
    for (std::size_t p = 0; p < calibration::kMeasurementPoints; ++p)
      out[p] = {r.waves[p].data(), r.waves[p].size(), sample_rate_hz};
    ++repeats_;
    return true;
  }
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
  if (!dynamics::simulate_rom(drivetrain_, dop, settings, st.outputs, &error_)) return false;
  const auto skip = static_cast<std::size_t>(std::llround(settle_s_ * sample_rate_hz));
  std::array<std::size_t, calibration::kMeasurementPoints> idx_of{};
  for (std::size_t p = 0; p < calibration::kMeasurementPoints; ++p) {
    const std::string channel = p < drivetrain_.measurement_points.size()
                                    ? drivetrain_.measurement_points[p].channel
                                    : std::string();
    const auto& ch = st.outputs.sensor_channels;
    std::size_t idx = ch.size();
    for (std::size_t c = 0; c < ch.size(); ++c)
      if (ch[c] == channel) idx = c;
    if (idx == ch.size() || st.outputs.acceleration_m_s2[idx].size() <= skip) {
      error_ = "dynamics model output has no usable channel '" + channel + "'";
      return false;
    }
    const std::vector<double>& a = st.outputs.acceleration_m_s2[idx];
    for (double v : a) {
      if (!std::isfinite(v)) {
        error_ = "dynamics model diverged (non-finite acceleration at '" + channel + "')";
        return false;
      }
    }
    idx_of[p] = idx;
  }
  // Remembered in the entry used longest ago (the one just returned is never it).
  RememberedRun& r = *std::min_element(
      st.runs.begin(), st.runs.end(),
      [](const RememberedRun& x, const RememberedRun& y) { return x.last_use < y.last_use; });
  r.params = params;
  r.effects = effects;
  r.op = op;
  r.sample_rate_hz = sample_rate_hz;
  r.duration_s = duration_s;
  r.last_use = st.calls;
  for (std::size_t p = 0; p < calibration::kMeasurementPoints; ++p) {
    const std::vector<double>& a = st.outputs.acceleration_m_s2[idx_of[p]];
    r.waves[p].assign(a.begin() + static_cast<std::ptrdiff_t>(skip), a.end());
    out[p] = {r.waves[p].data(), r.waves[p].size(), sample_rate_hz};
  }
  return true;
}

}  // namespace model::diagnosis
