#pragma once
// Vibration features of one measurement point that the paper's similarity
// indicators compare (VBDM-DT §2.3.2): the RMS of the time waveform and the
// order-tracked amplitudes of the fundamental and harmonics of every gear-mesh
// frequency.
//
// Thread context: construct at start-up (allocates the FFT plan and buffers);
// extract() is allocation-free and non-blocking; one owning thread.

#include <array>
#include <cstddef>
#include <vector>

#include "model/dsp/order_tracking.hpp"
#include "model/dsp/spectrum.hpp"

namespace model::dsp {

inline constexpr std::size_t kMaxMeshes = 4;     // gear stages whose mesh lines are tracked
inline constexpr std::size_t kMaxHarmonics = 5;  // fundamental + 4 harmonics per mesh
inline constexpr std::size_t kMaxAmplitudes = kMaxMeshes * kMaxHarmonics;

struct FeatureConfig {
  std::size_t samples_per_rev = 1024;  // [-] angle-domain samples per reference-shaft revolution
  std::size_t revolutions = 64;        // [-] revolutions per block (order resolution 1/revolutions)
  std::size_t harmonics = 3;  // [-] fundamental + (harmonics − 1) per mesh, ≤ kMaxHarmonics
  std::array<double, kMaxMeshes> mesh_orders{};  // [-] mesh frequency / reference-shaft frequency
  std::size_t mesh_count = 0;                    // [-] ≤ kMaxMeshes
  std::size_t lobe_half_width = 2;               // [lines] Hann main lobe summed per tone
  std::size_t noise_half_width =
      24;                         // [lines] neighbourhood of a tone whose median is its noise floor
  double resolved_ratio = 2.0;    // [-] tone resolved when amplitude ≥ ratio × noise floor
  double flat_threshold = 1e-12;  // [unit of x] smallest peak-to-peak accepted
  std::size_t max_pulses = 4096;  // [-] tacho pulse capacity
};

/// Features of one measurement point.
struct PointFeatures {
  double rms = 0.0;  // [unit of x] of the whole waveform, mean removed
  std::array<double, kMaxAmplitudes> amplitude{};  // [unit of x] index mesh·harmonics + (h − 1)
  /// [unit of x] what noise alone would read as this tone's amplitude: the
  /// median line of the tone's neighbourhood (main lobe excluded) × sqrt((2w+1)/ENBW).
  std::array<double, kMaxAmplitudes> noise_floor{};
  /// amplitude ≥ resolved_ratio × noise_floor: the tone stands out of the noise.
  /// Indicators use only tones the measurement resolves (see indicators.hpp).
  std::array<bool, kMaxAmplitudes> resolved{};
  std::size_t count = 0;  // [-] mesh_count · harmonics
  std::size_t resolved_count() const {
    std::size_t n = 0;
    for (std::size_t i = 0; i < count; ++i) n += resolved[i] ? 1 : 0;
    return n;
  }
};

class FeatureExtractor {
 public:
  explicit FeatureExtractor(const FeatureConfig& config);

  /// kOk, or kBadConfig when the sizes are impossible (FFT length not a power
  /// of two or too large, a harmonic above the angle-domain Nyquist order), or
  /// kTooShort when two tones (or a tone and DC) are closer than two Hann main
  /// lobes at this order resolution.
  DspStatus config_status() const { return config_status_; }
  const FeatureConfig& config() const { return config_; }

  /// Duration a recording must cover at a shaft speed [s] (plus the tracker margin).
  double required_duration_s(double shaft_hz) const;

  OrderTracker& tracker() { return tracker_; }

  /// Checks x (check_waveform), resamples it to the reference shaft's angle,
  /// and fills `out`. On any status but kOk, `out` is left unchanged.
  DspStatus extract(const double* x, std::size_t n, double fs_hz, const SpeedReference& speed,
                    PointFeatures& out);

  /// The angle-domain amplitude spectrum of the last successful extract()
  /// (lines() values, line k at order k/revolutions).
  const double* order_spectrum() const { return spectrum_.data(); }

 private:
  FeatureConfig config_;
  DspStatus config_status_ = DspStatus::kOk;
  SpectrumAnalyzer analyzer_;
  OrderTracker tracker_;
  std::vector<double> angle_;     // angle-domain block
  std::vector<double> spectrum_;  // its amplitude spectrum
  static constexpr std::size_t kMaxNoiseLines = 128;
  std::array<double, kMaxNoiseLines + 1> neighbours_{};  // noise-floor work buffer
};

}  // namespace model::dsp
