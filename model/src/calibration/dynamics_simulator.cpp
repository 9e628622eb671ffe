#include "model/calibration/dynamics_simulator.hpp"

#include <algorithm>
#include <cmath>

namespace model::calibration {

DynamicsSimulator::DynamicsSimulator(const Drivetrain& drivetrain, DynamicsModel model,
                                     double sample_rate_hz, double settle_s)
    : drivetrain_(drivetrain),
      model_(model),
      sample_rate_hz_(sample_rate_hz),
      settle_s_(settle_s) {}

bool DynamicsSimulator::simulate(const DynamicsParameters& params, const OperatingPoint& op,
                                 double duration_s,
                                 std::array<WaveformView, kMeasurementPoints>& out) {
  drivetrain_.dynamics = params;
  dynamics::SimulationSettings settings;
  settings.seconds = settle_s_ + duration_s;
  settings.sample_rate_hz = sample_rate_hz_;
  const dynamics::OperatingPoint dop{op.rotor_speed_rpm, op.input_torque_nm};
  const bool ok = model_ == DynamicsModel::kRom
                      ? dynamics::simulate_rom(drivetrain_, dop, settings, outputs_, &error_)
                      : dynamics::simulate_full(drivetrain_, dop, settings, outputs_, &error_);
  if (!ok) return false;
  skip_ = static_cast<std::size_t>(std::llround(settle_s_ * sample_rate_hz_));
  for (std::size_t p = 0; p < kMeasurementPoints; ++p) {
    const std::string channel = p < drivetrain_.measurement_points.size()
                                    ? drivetrain_.measurement_points[p].channel
                                    : std::string();
    std::size_t idx = outputs_.sensor_channels.size();
    for (std::size_t c = 0; c < outputs_.sensor_channels.size(); ++c) {
      if (outputs_.sensor_channels[c] == channel) idx = c;
    }
    if (idx == outputs_.sensor_channels.size() || outputs_.acceleration_m_s2[idx].size() <= skip_) {
      error_ = "dynamics model output has no usable channel '" + channel + "'";
      return false;
    }
    const std::vector<double>& a = outputs_.acceleration_m_s2[idx];
    for (double v : a) {
      if (!std::isfinite(v)) {
        error_ = "dynamics model diverged (non-finite acceleration at '" + channel + "')";
        return false;
      }
    }
    out[p] = {a.data() + skip_, a.size() - skip_, outputs_.sample_rate_hz};
  }
  return true;
}

double rom_sample_rate_hz(double highest_hz) {
  return std::max(4096.0, std::exp2(std::ceil(std::log2(6.0 * std::max(highest_hz, 1.0)))));
}

}  // namespace model::calibration
