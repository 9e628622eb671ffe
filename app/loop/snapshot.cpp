#include "loop/snapshot.hpp"

#include <algorithm>
#include <cmath>

namespace app::loop {

const char* to_string(VibrationZone zone) {
  switch (zone) {
    case VibrationZone::kUnknown:
      return "unknown";
    case VibrationZone::kAB:
      return "A/B";
    case VibrationZone::kC:
      return "C";
    case VibrationZone::kD:
      return "D";
  }
  return "?";
}

results::ResultsValues to_results_values(const Snapshot& s) {
  results::ResultsValues v;
  v.stamp_ns = s.stamp_ns;
  v.sequence = s.sequence;
  v.status_word = s.status_word;
  v.fault_word = s.fault_word;
  v.calibration_generation = s.calibration_generation;
  v.rotor_torque_nm = s.rotor_torque_nm;
  v.rotor_speed_rpm = s.rotor_speed_rpm;
  v.wind_speed_mps = s.wind_speed_mps;
  v.hss_speed_rpm = s.hss_speed_rpm;
  v.calibration_residual = s.calibration_residual;
  // Register order: point1_rms, point2_rms, point1_kurtosis, point2_kurtosis, residual,
  // fit_f1, fit_f2, fit_f3 (the worse of the two points: what decides a calibration).
  v.indicators[0] = s.points[0].rms_mps2;
  v.indicators[1] = s.points[1].rms_mps2;
  v.indicators[2] = s.points[0].kurtosis;
  v.indicators[3] = s.points[1].kurtosis;
  v.indicators[4] = s.calibration_residual;
  for (std::size_t k = 0; k < 3; ++k) {
    const float a = s.fit[0][k], b = s.fit[1][k];
    v.indicators[5 + k] = std::isnan(a) ? b : (std::isnan(b) ? a : std::max(a, b));
  }
  const std::size_t n = std::min<std::size_t>(s.channel_count, v.channels.size());
  for (std::size_t c = 0; c < n; ++c) v.channels[c] = s.channels[c];
  return v;
}

}  // namespace app::loop
