#pragma once
// What the calibrator needs from a dynamics model: parameters + operating
// point → the radial acceleration waveforms at the two measurement points.
// The dynamics ROM (model/dynamics/) and the lumped stand-in
// (lumped_simulator.hpp) both implement it.
//
// Thread context: simulate() runs on the calibrator's low-priority thread; an
// implementation allocates its buffers at construction and reuses them.

#include <array>
#include <cstddef>

#include "model/drivetrain/description.hpp"

namespace model::calibration {

inline constexpr std::size_t kMeasurementPoints = 2;  // point1 (hss, b5), point2 (ims, b3)

struct OperatingPoint {
  double rotor_speed_rpm = 0.0;  // [rpm] mean rotor (carrier) speed
  double input_torque_nm = 0.0;  // [N·m] mean rotor torque on the gearbox input
};

/// A waveform owned by the simulator, valid until its next simulate() call.
struct WaveformView {
  const double* samples = nullptr;  // [m/s²] radial acceleration
  std::size_t count = 0;
  double sample_rate_hz = 0.0;  // [Hz]
};

class VibrationSimulator {
 public:
  virtual ~VibrationSimulator() = default;
  /// Steady-state vibration at `op` with `params`, over at least `duration_s`.
  /// The shaft speeds are constant at their mean values (the waveforms are
  /// order-tracked with a constant speed).
  /// @return false when the model cannot produce a waveform (diverged, bad
  ///         parameters); `out` is then unspecified
  virtual bool simulate(const DynamicsParameters& params, const OperatingPoint& op,
                        double duration_s, std::array<WaveformView, kMeasurementPoints>& out) = 0;
};

}  // namespace model::calibration
