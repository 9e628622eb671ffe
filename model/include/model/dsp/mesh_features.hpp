#pragma once
// Vibration features of one measurement point that the paper's similarity
// indicators compare (VBDM-DT §2.3.2): the RMS of the time waveform and the
// order-tracked amplitudes of the fundamental and harmonics of every gear-mesh
// frequency.
//
// Tone amplitudes: every known line of the drivetrain near a compared tone — the
// other mesh harmonics and the low harmonics of every shaft (an unbalance line at a
// shaft's 1×, a misalignment line at 2×) — is fitted at once, by linear least squares
// of the Hann-windowed complex spectrum against the window's kernel at each line's
// exact (fractional) order, over ±fit_half_width lines around each line:
//   X(k) = Σ_j c_j·W(ν_j − k),  W(δ) = Σ_n w[n]·e^{i2πδn/N},  A_j = 2|c_j|
// (ν_j the line's order × revolutions). Two lines closer than a Hann main lobe — the
// planetary mesh at 0.961 hss orders and the hss 1× line at 64 revolutions are 2.5
// lines apart — are thus separated instead of summed. A compared tone that a known
// line overlaps too closely to separate (the fit's variance inflation for it above
// max_variance_inflation) is flagged `separable = false` and left out of the
// indicators, like a tone below the noise. Lines the drivetrain does not predict are
// not in the fit: they bias a tone only inside its ±fit_half_width lines.
//
// Thread context: construct at start-up (allocates the FFT plan, buffers and the
// fit's pseudo-inverse, which depends on the configuration only); extract() is
// allocation-free and non-blocking; one owning thread.

#include <array>
#include <complex>
#include <cstddef>
#include <vector>

#include "model/dsp/order_tracking.hpp"
#include "model/dsp/spectrum.hpp"

namespace model::dsp {

inline constexpr std::size_t kMaxMeshes = 4;     // gear stages whose mesh lines are tracked
inline constexpr std::size_t kMaxHarmonics = 5;  // fundamental + 4 harmonics per mesh
inline constexpr std::size_t kMaxAmplitudes = kMaxMeshes * kMaxHarmonics;
inline constexpr std::size_t kMaxShafts =
    6;  // shafts whose low harmonics are fitted as known lines

struct FeatureConfig {
  std::size_t samples_per_rev = 1024;  // [-] angle-domain samples per reference-shaft revolution
  std::size_t revolutions = 64;        // [-] revolutions per block (order resolution 1/revolutions)
  std::size_t harmonics = 3;  // [-] fundamental + (harmonics − 1) per mesh, ≤ kMaxHarmonics
  std::array<double, kMaxMeshes> mesh_orders{};  // [-] mesh frequency / reference-shaft frequency
  std::size_t mesh_count = 0;                    // [-] ≤ kMaxMeshes
  /// [-] shaft frequency / reference-shaft frequency of every shaft (reference included):
  /// their harmonics 1..shaft_harmonics are fitted as known lines, not compared.
  std::array<double, kMaxShafts> shaft_orders{};
  std::size_t shaft_count = 0;      // [-] ≤ kMaxShafts
  std::size_t shaft_harmonics = 3;  // [-]
  std::size_t extra_mesh_harmonics =
      2;                                // [-] mesh harmonics above `harmonics` fitted, not compared
  std::size_t lobe_half_width = 3;      // [lines] each line's fit takes ±this many lines (≥ 2)
  double max_variance_inflation = 2.0;  // [-] above: a tone is not separable from its neighbours
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
  /// [rad] phase of each tone at the analysis block's first sample (comparable between
  /// waveforms that start at the same shaft angle, e.g. two simulations of one model)
  std::array<double, kMaxAmplitudes> phase{};
  /// [unit of x] what noise alone would read as this tone's amplitude: the RMS of the fit's
  /// estimate when the spectrum around it is noise of the level of the neighbourhood's
  /// median line (known lines' lobes excluded).
  std::array<double, kMaxAmplitudes> noise_floor{};
  /// amplitude ≥ resolved_ratio × noise_floor and the tone separable from its known
  /// neighbours. Indicators use only tones the measurement resolves (see indicators.hpp).
  std::array<bool, kMaxAmplitudes> resolved{};
  /// false when a known line sits too close to the tone to be separated (see the header).
  std::array<bool, kMaxAmplitudes> separable{};
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
  /// kTooShort when two compared tones cannot be separated at this order resolution
  /// (variance inflation above max_variance_inflation) or a tone lies within a main
  /// lobe of DC.
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

  /// Compared tone i's variance inflation in the fit (1: no neighbour shares its lines).
  double variance_inflation(std::size_t i) const { return inflation_[i]; }

 private:
  void build_fit();

  FeatureConfig config_;
  DspStatus config_status_ = DspStatus::kOk;
  SpectrumAnalyzer analyzer_;
  OrderTracker tracker_;
  std::vector<double> angle_;     // angle-domain block
  std::vector<double> spectrum_;  // its amplitude spectrum
  // The fit (header): for compared tone i, c_i = Σ_r fit_[i][r]·X(fit_bins_[r]).
  std::vector<int> fit_bins_;
  std::array<std::vector<std::complex<double>>, kMaxAmplitudes> fit_{};
  std::array<double, kMaxAmplitudes> fit_norm_{};   // ‖fit_[i]‖ (noise gain)
  std::array<double, kMaxAmplitudes> inflation_{};  // variance inflation
  std::vector<char> excluded_;  // per line: inside a known line's lobe (not noise)
  static constexpr std::size_t kMaxNoiseLines = 128;
  std::array<double, kMaxNoiseLines + 1> neighbours_{};  // noise-floor work buffer
};

}  // namespace model::dsp
