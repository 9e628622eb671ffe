#pragma once
// The twin's dynamics model (model/dynamics/simulate.hpp) behind the
// calibrator's simulator interface (simulator.hpp): the reduced-order model
// the box runs (kRom, what the calibrator calibrates) or the full-order
// Newmark reference (kFull, what the synthetic "measured" recordings of
// tools/calibration come from, so that truth and calibration model differ).
//
// Both start from the static deflection, so each call simulates `settle_s`
// first and returns the waveforms after it (the transient of the static start
// decays with the Rayleigh damping; the returned part is the steady state the
// indicators compare).
//
// Thread context: simulate() allocates (the dynamics model is built per call
// and its outputs are vectors): the calibrator's low-priority thread or a host
// tool, never the real-time loop. One owning thread.
#include <string>

#include "model/calibration/simulator.hpp"
#include "model/drivetrain/description.hpp"
#include "model/dynamics/simulate.hpp"

namespace model::calibration {

enum class DynamicsModel : unsigned char { kRom, kFull };

class DynamicsSimulator : public VibrationSimulator {
 public:
  /// @param drivetrain     copied; its `dynamics` are replaced by each call's parameters
  /// @param model          ROM or full-order model
  /// @param sample_rate_hz [Hz] output rate (the ROM steps at it; the full model at 2× it)
  /// @param settle_s       [s] simulated and discarded before the returned waveforms
  DynamicsSimulator(const Drivetrain& drivetrain, DynamicsModel model, double sample_rate_hz,
                    double settle_s);

  bool simulate(const DynamicsParameters& params, const OperatingPoint& op, double duration_s,
                std::array<WaveformView, kMeasurementPoints>& out) override;

  /// The dynamics model's message for the last failed call.
  const std::string& error() const { return error_; }
  /// hss revolutions (nominal angle / 2π) of the returned samples, for a tacho.
  const double* hss_revolutions() const { return outputs_.hss_revolutions.data() + skip_; }

 private:
  Drivetrain drivetrain_;
  DynamicsModel model_;
  double sample_rate_hz_;
  double settle_s_;
  std::size_t skip_ = 0;
  dynamics::SimulationOutputs outputs_;
  std::string error_;
};

/// Output rate for calibrating with the ROM: the smallest power of two ≥ 6 × the
/// highest compared frequency (and ≥ 4096 Hz). The ROM interpolates its forces
/// linearly over a step, which scales a harmonic at f by sinc²(π·f/fs) (rom.hpp):
/// ≥ 0.91 at f ≤ fs/6, a bias the calibration absorbs well within the thresholds.
double rom_sample_rate_hz(double highest_hz);

}  // namespace model::calibration
