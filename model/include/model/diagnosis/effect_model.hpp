#pragma once
// What the diagnosis needs from the dynamics model to model a hypothesis: the
// calibrated ROM with the hypothesis's effect term switched on, at given effect
// parameters. The effect terms themselves live in model/dynamics (every effect of
// the contract a switchable term of the full and reduced models); this interface
// is the seam, so that the diagnosis does not depend on how a term is assembled.
//
// Thread context: the diagnosis's low-priority thread; simulate() allocates (the
// dynamics model is built per call).

#include <array>
#include <cstddef>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "model/calibration/simulator.hpp"
#include "model/diagnosis/signatures.hpp"

namespace model::diagnosis {

inline constexpr std::size_t kMaxEffectParameters = 4;

/// One fitted parameter of an effect term.
struct EffectParameter {
  std::string name;    // as reported: "stiffness_loss", "eccentricity_m", ...
  double lower = 0.0;  // bounds of the fit
  double upper = 1.0;
  double initial = 0.1;   // where the fit starts
  bool log_scale = true;  // searched as a logarithm (a severity spans decades)
};

/// An effect switched on: the hypothesis, its parameter values, and what the recording
/// says about its rate (a bearing's defect frequency including slip).
struct EffectSetting {
  const Hypothesis* hypothesis = nullptr;
  std::array<double, kMaxEffectParameters> values{};
  double measured_rate_order = 0.0;  // [orders of the reference] 0: the nominal rate
};

class EffectSimulator {
 public:
  virtual ~EffectSimulator() = default;
  /// The parameters of `h`'s term; empty when this simulator cannot switch it on.
  virtual std::vector<EffectParameter> parameters(const Hypothesis& h) const = 0;
  /// Steady-state vibration at both measurement points over `duration_s` after the
  /// model's settling, at a constant speed, with `params` and the effects of `effects`.
  /// @return false when the model cannot produce a waveform; `error()` says why
  virtual bool simulate(
      const DynamicsParameters& params, const std::vector<EffectSetting>& effects,
      const calibration::OperatingPoint& op, double sample_rate_hz, double duration_s,
      std::array<calibration::WaveformView, calibration::kMeasurementPoints>& out) = 0;
  virtual const std::string& error() const = 0;
};

/// The twin's dynamics ROM (model/dynamics/simulate.hpp) behind EffectSimulator: the
/// effect terms model/dynamics provides are switched on per call.
///
/// A call with exactly the inputs of one of the last kRemembered distinct calls (the same
/// parameters bit for bit, effects, operating point, rate and duration) returns that call's
/// waveforms without simulating again: the model is deterministic, so they are the ones a
/// new simulation would give. The calibrator evaluates each round's start point twice more
/// after it was evaluated (the excitation's T, the identification's base), and a hold-out
/// simulation can repeat a fit's best evaluation. Views stay valid until the entry they
/// point into is replaced: at least until the next call, as the interface promises. Memory:
/// kRemembered copies of the two returned waveforms (a calibration evaluation's 64
/// revolutions at 8–16 kHz: 0.6–1.3 MB each).
class RomEffectSimulator : public EffectSimulator {
 public:
  /// @param settle_s [s] simulated and discarded before the returned waveforms
  RomEffectSimulator(const Drivetrain& drivetrain, double settle_s);
  ~RomEffectSimulator() override;
  std::vector<EffectParameter> parameters(const Hypothesis& h) const override;
  bool simulate(
      const DynamicsParameters& params, const std::vector<EffectSetting>& effects,
      const calibration::OperatingPoint& op, double sample_rate_hz, double duration_s,
      std::array<calibration::WaveformView, calibration::kMeasurementPoints>& out) override;
  const std::string& error() const override { return error_; }
  /// [-] calls answered from a remembered simulation (not simulated again)
  std::size_t repeats() const { return repeats_; }
  static constexpr std::size_t kRemembered = 8;

 private:
  struct State;
  Drivetrain drivetrain_;
  std::size_t repeats_ = 0;
  double settle_s_;
  std::unique_ptr<State> state_;
  std::string error_;
};

/// An EffectSimulator with fixed effects and a fixed rate behind the calibrator's
/// VibrationSimulator interface: calibration with the effect switched on.
class EffectCalibrationAdapter : public calibration::VibrationSimulator {
 public:
  EffectCalibrationAdapter(EffectSimulator& simulator, double sample_rate_hz)
      : simulator_(simulator), sample_rate_hz_(sample_rate_hz) {}
  void set_effects(std::vector<EffectSetting> effects) { effects_ = std::move(effects); }
  bool simulate(
      const DynamicsParameters& params, const calibration::OperatingPoint& op, double duration_s,
      std::array<calibration::WaveformView, calibration::kMeasurementPoints>& out) override {
    return simulator_.simulate(params, effects_, op, sample_rate_hz_, duration_s, out);
  }

 private:
  EffectSimulator& simulator_;
  double sample_rate_hz_;
  std::vector<EffectSetting> effects_;
};

}  // namespace model::diagnosis
