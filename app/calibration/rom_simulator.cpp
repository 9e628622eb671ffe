#include "calibration/rom_simulator.hpp"

#include <cmath>

namespace app::calibration {

RomSimulator::RomSimulator(const model::Drivetrain& drivetrain, double sample_rate_hz, double settle_s)
    : drivetrain_(drivetrain), sample_rate_hz_(sample_rate_hz), settle_s_(settle_s) {}

bool RomSimulator::simulate(const model::DynamicsParameters& params, const model::calibration::OperatingPoint& op,
                            double duration_s,
                            std::array<model::calibration::WaveformView, model::calibration::kMeasurementPoints>& out) {
  drivetrain_.dynamics = params;
  model::dynamics::SimulationSettings settings;
  settings.seconds = settle_s_ + duration_s;
  settings.sample_rate_hz = sample_rate_hz_;
  if (!model::dynamics::simulate_rom(drivetrain_, {op.rotor_speed_rpm, op.input_torque_nm}, settings, outputs_,
                                     &error_)) {
    return false;
  }
  const auto skip = static_cast<std::size_t>(std::llround(settle_s_ * sample_rate_hz_));
  for (std::size_t p = 0; p < model::calibration::kMeasurementPoints; ++p) {
    const std::string& channel = p < drivetrain_.measurement_points.size() ? drivetrain_.measurement_points[p].channel
                                                                           : std::string();
    std::size_t idx = outputs_.sensor_channels.size();
    for (std::size_t c = 0; c < outputs_.sensor_channels.size(); ++c) {
      if (outputs_.sensor_channels[c] == channel) idx = c;
    }
    if (idx == outputs_.sensor_channels.size() || outputs_.acceleration_m_s2[idx].size() <= skip) {
      error_ = "ROM output has no usable channel '" + channel + "'";
      return false;
    }
    const std::vector<double>& a = outputs_.acceleration_m_s2[idx];
    out[p] = {a.data() + skip, a.size() - skip, outputs_.sample_rate_hz};
  }
  return true;
}

}  // namespace app::calibration
