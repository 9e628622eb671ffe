#pragma once
// A recording bundle measured for calibration: the one measurement `drivetwin calibrate`
// calibrates against, shared with the host tools that compare calibrators on the same
// measurement (tools/calibration/calibration_bench --bundle).
//
// Windows of the feature configuration's hss revolutions, back to back from the start of the
// recording (from the tacho's pulses when it has one on the hss, else the speed reference's
// mean speed), as many as fit up to `windows`: the tone amplitudes, noise floors and RMS of
// both measurement points averaged in power (a tone is resolved when its averaged amplitude
// stands out of its averaged floor), and each point's order spectrum averaged in power.
//
// Thread context: command / host code (reads files, allocates, throws).

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "model/calibration/calibrator.hpp"
#include "model/dsp/mesh_features.hpp"
#include "recording/bundle_check.hpp"

namespace app::recording {

// `drivetwin calibrate`'s settings that a host tool must share to calibrate as it does.
/// [Hz] band of the spectral residual ρ (diagnosis-report.md: order-tracked energy 0–5 kHz)
inline constexpr double kCalibrateResidualBandHz = 5000.0;
/// [-] σ_ρ of the spectral residual row (`calibrate --residual-sd`'s default)
inline constexpr double kCalibrateResidualSd = 0.25;
/// [Hz] the rate the calibration's ROM runs at: the recording's, within 8192 … 51200 Hz
inline double calibrate_simulator_rate_hz(double recording_rate_hz) {
  return std::clamp(recording_rate_hz, 8192.0, 51200.0);
}
/// The trust region's seed for calibrate's `--seed`: seed 1 (the default) probes along the axes
inline std::uint64_t calibrate_trust_region_seed(std::uint64_t seed) {
  return seed == 1 ? 0 : seed;
}

struct CalibrationMeasurement {
  std::filesystem::path dir;
  CheckedBundle bundle;
  std::string speed_source;  // the speed reference's source (signal/speed_reference.hpp)
  double hss_hz = 0.0;       // [Hz] mean hss speed of the reference
  std::size_t windows = 0;   // [-] windows averaged
  model::calibration::CalibrationCase measured;  // features of both points, operating point
  // Power-averaged order spectrum amplitudes per point (FeatureExtractor::order_spectrum()).
  std::array<std::vector<double>, model::calibration::kMeasurementPoints> spectrum;
};

/// Loads the bundle at `dir` (load_bundle, `drivetrain_override` as its option) and measures
/// it with `fx` (whose configuration is the calibrator's feature configuration) over up to
/// `max_windows` windows (≥ 1).
/// @throws BundleCheckError naming the file and channel: a bundle that fails its checks, a
///         missing measurement-point channel, a flat or clipped or non-finite channel, a
///         recording shorter than one window, a tacho with too few pulses, fewer than
///         kMinTones mesh harmonics out of the noise at a point
CalibrationMeasurement measure_for_calibration(const std::filesystem::path& dir,
                                               std::size_t max_windows,
                                               model::dsp::FeatureExtractor& fx,
                                               const std::string& drivetrain_override);

}  // namespace app::recording
