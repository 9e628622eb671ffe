#pragma once
// One recording of the independent lumped gearbox (lumped_gearbox.hpp) as a case of the
// diagnosis benchmark: the effect, the operating point, what the measurement adds (noise,
// a slow speed drift, gain errors, a tacho or none), the parameter drift, and the
// concealment figures; optionally the severity scaled until the effect is concealed with
// its strongest line 8–20 dB below the tenth peak (hidden, not vanished).
// Host tool: allocates and throws.

#include <string>

#include "concealment.hpp"
#include "hal/recording_bundle.hpp"
#include "lumped_gearbox.hpp"

namespace tools::diagnosis {

struct LumpedCaseSpec {
  std::string id;
  LumpedEffect effect;  // effect.effect empty: a control (parameter drift only)
  double rpm = 8.33, torque_nm = 361747.0;
  double seconds = 30.0, fs_hz = 25600.0;
  double drift = 0.02, drift_period_s = 23.0;
  double noise = 0.05, gain_error = 0.1;
  bool tacho = false;
  double stiffness_scale = 1.0, damping_scale = 1.0;
  bool conceal = false;  // scale the severity (≤ 8 tries) to a concealed 8–20 dB margin
  unsigned seed = 1;
};

struct LumpedCase {
  LumpedCaseSpec spec;  // as run (severity after concealment)
  hal::Recording recording;
  Concealment concealment;  // zero for a control
  bool concealed = false;
};

LumpedCase make_lumped_case(const model::Drivetrain& drivetrain, const LumpedCaseSpec& spec);

/// The case's ground truth as JSON text: {"generator", "case", "effect", "location",
/// "severity", "concealed", "rms_change", "line_margin_db", ...}.
std::string lumped_truth_json(const LumpedCase& c);

}  // namespace tools::diagnosis
