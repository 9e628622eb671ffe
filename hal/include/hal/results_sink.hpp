#pragma once
// Results sink: what the twin publishes for the turbine controller / SCADA to
// read (the Modbus server of hal/README.md's register map, or a recorder).
//
// Thread context: publish() from the RT thread: copies into a seqlock
// (LatestValue), wait-free; the server's own thread serves it to clients.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "hal/clock.hpp"
#include "hal/device.hpp"

namespace hal {

/// Components with per-component results, in register-map order (v1). The ids
/// are the component ids of recording-bundle.md for the reference drivetrain.
inline constexpr std::array<std::string_view, 19> kResultComponents{
    "sun",    "planet",    "ring", "g1",  "g2", "g3", "g4",  // gears
    "b1",     "b2",        "b3",   "b4",  "b5", "b6", "pb",  // bearings
    "lss",    "sun_shaft", "ims",  "hss",                    // shafts
    "carrier"};
inline constexpr std::size_t kResultComponentCount = kResultComponents.size();

/// Condition indicators, in register-map order (v1).
inline constexpr std::array<std::string_view, 8> kResultIndicators{
    "point1_rms_mps2", "point2_rms_mps2", "point1_kurtosis", "point2_kurtosis",
    "residual",        "fit_f1",          "fit_f2",          "fit_f3"};
inline constexpr std::size_t kResultIndicatorCount = kResultIndicators.size();

/// Bits of TwinResults::status_word.
enum StatusBit : std::uint16_t {
  kStatusRunning = 1u << 0,   // loop running
  kStatusDegraded = 1u << 1,  // some input invalid/stale; results held or estimated
  kStatusScadaStale = 1u << 2,
  kStatusCmsFault = 1u << 3,  // CAN gaps / bus-off / silent
  kStatusKeyphasorFault = 1u << 4,
  kStatusCalibrated = 1u << 5,  // model parameters calibrated
  kStatusAlarm = 1u << 6,       // alarm relay raised
  kStatusOverrun = 1u << 7,     // a cycle overran since the last publish
};

struct ComponentResult {
  float load = 0.0f;    // [N·m] shafts/gears: torque; [N] bearings: radial load
  float damage = 0.0f;  // [-] accumulated Miner damage (0..1 = life used)
  float rul_h = 0.0f;   // [h] remaining useful life estimate
};

struct TwinResults {
  Timestamp stamp{0};            // [ns] loop time of the results
  std::uint32_t sequence = 0;    // [-] publish counter
  float rotor_torque_nm = 0.0f;  // [N·m] estimated gearbox input torque
  float rotor_speed_rpm = 0.0f;  // [rpm]
  float wind_speed_mps = 0.0f;   // [m/s] used by the model
  float hss_speed_rpm = 0.0f;    // [rpm] from the keyphasor
  std::array<ComponentResult, kResultComponentCount> components{};
  std::array<float, kResultIndicatorCount> indicators{};
  std::uint16_t status_word = 0;  // StatusBit
  std::uint16_t fault_word = 0;   // app-defined fault codes (bit per supervisor fault)
  std::uint16_t calibration_word =
      0;  // [-] calibration generation (increments on each applied calibration)
  float calibration_residual = 0.0f;  // [-] residual of the last calibration
};

class ResultsSink : public Device {
 public:
  /// Makes `results` the values served from now on. Wait-free.
  virtual Status publish(const TwinResults& results) = 0;
};

}  // namespace hal
