#pragma once
// The truth synthesizer's core (tools/truth/README.md): recordings of the full-order
// dynamics model (model/dynamics/full_model.hpp, Newmark, the carrier turning) with one
// effect of the diagnosis contract at a chosen severity, plus what a real measurement adds —
// sensor noise, a slow speed drift, sensor gain errors, impact-time jitter, a tacho or none,
// dynamics parameters off nominal — and, per case, whether the effect is *concealed*:
// it changes each channel's RMS by less than 10 % and its strongest spectral line is at
// least 6 dB below the tenth-highest peak of the raw spectrum.
//
// Host tool code: allocates and throws.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "model/drivetrain/description.hpp"

namespace truth {

inline constexpr double kConcealedRmsChange = 0.10;  // [-] |ΔRMS|/RMS below this ...
inline constexpr double kConcealedMarginDb = 6.0;    // [dB] ... and the line this far below

/// What a real measurement adds to the model's waveforms.
struct Measurement {
  double noise = 0.05;                   // [-] white-noise RMS / the healthy channel's RMS
  double drift = 0.02;                   // [-] amplitude of the slow speed drift (sinusoidal)
  double drift_period_s = 45.0;          // [s]
  double drift_phase_rad = 0.0;          // [rad]
  std::array<double, 2> gain{1.0, 1.0};  // [-] sensor gain of point1, point2 (±10 %)
  bool tacho = true;                     // a once-per-revolution pulse on the hss
  double jitter = 0.01;                  // [-] random spread of a bearing defect's impact spacing
};

/// One recording to make.
struct CaseSpec {
  std::string id;
  std::string note;                     // free text for the case list
  double rotor_rpm = 8.33;              // [rpm] nominal (the drift is about it)
  double torque_nm = 361747.0;          // [N·m]
  double seconds = 16.0;                // [s] recorded
  double settle_s = 1.0;                // [s] simulated and discarded first
  double sample_rate_hz = 25600.0;      // [Hz]
  int substeps = 2;                     // Newmark steps per sample
  std::optional<model::Effect> effect;  // none: a control (parameter drift only)
  bool conceal = false;                 // scale the effect's severity parameter to be concealed
  double offset_spread = 1.0;           // [-] × the default spread of the parameter offsets
  Measurement measurement;
  std::uint64_t seed = 1;
};

/// Concealment figures of one channel.
struct ChannelConcealment {
  std::string channel;
  double rms_change = 0.0;      // [-] RMS with the effect / without − 1
  double effect_line_hz = 0.0;  // [Hz] the effect's strongest line (spectrum of the difference)
  double effect_line = 0.0;     // [m/s²] its amplitude
  double tenth_peak = 0.0;      // [m/s²] the tenth-highest peak of the raw spectrum
  double margin_db = 0.0;       // [dB] 20·log10(effect_line / tenth_peak) (negative: below)
  bool concealed = false;
};

struct CaseResult {
  CaseSpec spec;                             // as run (the severity after concealment scaling)
  model::DynamicsParameters parameters;      // the truth's dynamics parameters (off nominal)
  double mean_rotor_rpm = 0.0;               // [rpm] over the recording
  std::vector<std::vector<double>> samples;  // point1, point2 [m/s²] (+ tacho [V])
  std::vector<ChannelConcealment> concealment;
  bool concealed = false;  // every channel concealed (false for a control)
  int severity_tries = 0;
};

/// Welch-averaged Hann amplitude spectrum (blocks of `nfft`, half overlapped; model/dsp).
std::vector<double> welch_amplitude(const std::vector<double>& x, std::size_t nfft);
/// The tenth-highest local maximum of a spectrum (a line above both neighbours).
double tenth_highest_peak(const std::vector<double>& spectrum);
/// Concealment of an effect in one channel: `raw` the recording, `without` the same
/// recording without the effect (same noise, drift and gains).
ChannelConcealment concealment(const std::string& channel, const std::vector<double>& raw,
                               const std::vector<double>& without, double sample_rate_hz);

/// The dynamics parameters of a case: nominal ones moved by seeded random offsets
/// (mesh stiffness ±10 %, bearing stiffness ±15 %, η and ζ ±30 %, × spread).
model::DynamicsParameters off_nominal(const model::DynamicsParameters& nominal, double spread,
                                      std::uint64_t seed);

/// Simulates a case. Throws std::runtime_error with the reason on a bad case.
CaseResult run_case(const model::Drivetrain& drivetrain, const CaseSpec& spec);

/// Writes the bundle (recording-bundle.md) of a result to `dir`.
void write_case_bundle(const CaseResult& result, const std::string& dir);
/// The case's ground truth as JSON text (effect, location, parameters, measurement,
/// concealment figures).
std::string truth_json(const CaseResult& result);

}  // namespace truth
