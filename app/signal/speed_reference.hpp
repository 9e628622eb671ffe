#pragma once
// The speed reference for order tracking a vibration window: the one choice, used by
// `drivetwin calibrate` on a recording and by the calibration thread on a live CMS window
// (whose keyphasor edges are mapped into the window's time base, signal/clock_mapping.hpp).
//
// In order of preference:
//   1. once-per-revolution pulses on the high-speed shaft (a tacho channel, or keyphasor
//      edges) when there are at least `min_pulses`: the order tracker follows the speed
//      pulse by pulse;
//   2. the SCADA rotor speed (mean over the window) × the gearbox ratio;
//   3. the high-speed mesh line of point 1, searched ±3 % around the nominal speed;
//   4. the nominal (operating point) speed.
//
// Thread context: non-real-time (the FFT of step 3 allocates its work buffers); one call
// per window on the calibration thread or in a command.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "model/drivetrain/kinematics.hpp"

namespace app::signal {

/// Search half-width of the mesh line around the nominal speed [-].
inline constexpr double kMeshLineSearch = 0.03;
/// FFT length of the mesh-line search.
inline constexpr std::size_t kMeshLineFft = 65536;

struct SpeedEvidence {
  std::vector<double> hss_pulses_s;       // [s] once-per-rev pulse times in the window's base
  std::size_t min_pulses = 0;             // [-] fewer pulses than this: not used
  std::optional<double> scada_rotor_rpm;  // [rpm] mean over the window
  const double* point1 = nullptr;         // point-1 acceleration, for the mesh line
  std::size_t samples = 0;
  double sample_rate_hz = 0.0;     // [Hz]
  double nominal_rotor_rpm = 0.0;  // [rpm] the operating point's
};

struct SpeedReference {
  std::string source;          // "tacho", "scada", "mesh line", "operating point"
  std::vector<double> pulses;  // [s] when source == "tacho"
  double hss_hz = 0.0;         // [Hz] otherwise
  /// Mean high-speed shaft speed [Hz] whichever the source.
  double mean_hss_hz() const;
};

SpeedReference choose_speed_reference(const SpeedEvidence& evidence,
                                      const model::Kinematics& kinematics);

}  // namespace app::signal
