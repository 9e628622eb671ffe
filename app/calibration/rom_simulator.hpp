#pragma once
// The dynamics ROM (model/dynamics/simulate.hpp) behind the calibrator's
// simulator interface (model/calibration/simulator.hpp).
//
// The ROM starts from the static deflection, so each call simulates a settling
// time first and returns the waveforms after it. Allocates on every call (the
// ROM builds its model and outputs): the calibrator's low-priority thread only,
// never the real-time loop.
#include <string>

#include "model/calibration/simulator.hpp"
#include "model/drivetrain/description.hpp"
#include "model/dynamics/simulate.hpp"

namespace app::calibration {

class RomSimulator : public model::calibration::VibrationSimulator {
 public:
  /// @param drivetrain     copied; its `dynamics` are replaced per call
  /// @param sample_rate_hz [Hz] ROM step and output rate
  /// @param settle_s       [s] simulated and discarded before the returned waveforms
  RomSimulator(const model::Drivetrain& drivetrain, double sample_rate_hz, double settle_s);

  bool simulate(const model::DynamicsParameters& params, const model::calibration::OperatingPoint& op,
                double duration_s,
                std::array<model::calibration::WaveformView, model::calibration::kMeasurementPoints>& out) override;

  /// The ROM's message for the last failed call.
  const std::string& error() const { return error_; }

 private:
  model::Drivetrain drivetrain_;
  double sample_rate_hz_;
  double settle_s_;
  model::dynamics::SimulationOutputs outputs_;
  std::string error_;
};

}  // namespace app::calibration
