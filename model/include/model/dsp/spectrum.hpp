#pragma once
// Amplitude spectra of vibration waveforms through kissfft (Debian libkissfft-dev,
// the header-only C++ template `kissfft.hh` in double precision).
//
// Thread context: construct at start-up (allocates the FFT plan, window and
// work buffers; kissfft's constructor itself allocates its twiddle table).
// Every call afterwards is allocation-free, lock-free and non-blocking, and may
// run on any single thread that owns the object (not thread-safe: one owner).

#include <complex>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace model::dsp {

/// Largest FFT the project plans for: 2^17 points (e.g. 1024 samples per
/// revolution × 128 revolutions). Larger requests make an invalid analyzer.
inline constexpr std::size_t kMaxFftSize = std::size_t{1} << 17;

/// Outcome of a signal-processing call; the text of each is in to_string().
enum class DspStatus : std::uint8_t {
  kOk,
  kBadConfig,  // analyzer/extractor configured with an impossible size
  kTooShort,   // fewer revolutions than the frequency resolution needs
  kFlat,       // no variation: sensor or cable dead
  kClipped,    // the waveform saturates (flat tops at its extreme values)
  kNonFinite,  // NaN or Inf in the samples
  kNoSpeed,    // no usable speed reference (tacho pulses, speed, mesh line)
};

/// A short English description of `status` (static storage).
const char* to_string(DspStatus status);

/// Hann-windowed single-sided amplitude spectrum of a real block of `size()`
/// samples, computed with a real-input kissfft plan of half that length.
class SpectrumAnalyzer {
 public:
  /// @param nfft block length, a power of two in [16, kMaxFftSize]. Powers of
  ///        two keep kissfft on its radix-2/4 butterflies, the only ones that
  ///        never allocate scratch memory during a transform.
  explicit SpectrumAnalyzer(std::size_t nfft);
  ~SpectrumAnalyzer();
  SpectrumAnalyzer(const SpectrumAnalyzer&) = delete;
  SpectrumAnalyzer& operator=(const SpectrumAnalyzer&) = delete;

  bool valid() const { return nfft_ != 0; }
  std::size_t size() const { return nfft_; }
  /// Number of spectral lines written by amplitude_spectrum(): nfft/2 + 1.
  std::size_t lines() const { return nfft_ / 2 + 1; }

  /// Amplitude spectrum of x[0..size()): the block mean is removed, a Hann
  /// window w[n] = 0.5·(1 − cos(2πn/N)) applied, and the result scaled by the
  /// amplitude correction 2/Σw[n] so that a sine of amplitude A centred on a
  /// line reads A on that line (DC and Nyquist lines are scaled by 1/Σw).
  /// @param x   `size()` samples [any unit]
  /// @param out `lines()` amplitudes [same unit as x], line k at k·fs/N
  void amplitude_spectrum(const double* x, double* out);

  /// Amplitude of a sinusoid near line `centre_line`, from the energy of the
  /// Hann main lobe: A = sqrt(Σ_{k=c−w}^{c+w} a_k² / ENBW) with ENBW = 1.5 lines
  /// for the Hann window (Harris 1978, Table 1). Unlike the peak line, this is
  /// insensitive to where the sinusoid falls between lines (no scalloping loss).
  /// @param spectrum  amplitude spectrum from amplitude_spectrum()
  /// @param half_width w ≥ 2 lines; lines outside the spectrum are ignored
  double tone_amplitude(const double* spectrum, double centre_line, std::size_t half_width) const;

  /// The complex transform of the last amplitude_spectrum() call, X(k) = Σ_n x_w[n]·e^{−i2πkn/N}
  /// for k = 1 .. size()/2 − 1 (the windowed block, no amplitude gain); index 0 packs DC and
  /// Nyquist (kissfft's real-input layout).
  const std::complex<double>* complex_spectrum() const;

  /// Σ_n w[n]·e^{i2πδn/N}: the window's kernel at δ lines (a tone c·e^{i2πνn/N} reads
  /// c·window_kernel(ν − k) at line k of complex_spectrum()).
  std::complex<double> window_kernel(double delta_lines) const;

  /// Hann equivalent noise bandwidth in lines.
  static constexpr double kHannEnbwLines = 1.5;

 private:
  struct Plan;
  std::size_t nfft_ = 0;
  std::unique_ptr<Plan> plan_;
  std::vector<double> window_;    // [-] Hann window, nfft
  std::vector<double> windowed_;  // work buffer, nfft
  double amplitude_gain_ = 0.0;   // [-] 2/Σw
};

/// RMS of x[0..n) about its mean: sqrt(1/n·Σ(x − x̄)²). 0 for n = 0.
double rms(const double* x, std::size_t n);

/// The sums of the share of a recording's spectral energy a simulation does not explain (the
/// residual of shared/reference/diagnosis-report.md: Σ(a_m − a_s)² / Σ a_m²), over lines
/// 1..last of a measured and a simulated amplitude spectrum, added to `miss` and `total` so
/// that channels sum up. A simulated line beyond `simulated_lines` counts 0; lines beyond
/// `measured_lines` are not read.
void add_unexplained_energy(const double* measured, std::size_t measured_lines,
                            const double* simulated, std::size_t simulated_lines, std::size_t last,
                            double& miss, double& total);

/// Checks a waveform before it is analysed: non-finite samples, a flat
/// channel (peak-to-peak ≤ flat_threshold) or clipping (more than 0.1 % of the
/// samples sit in runs of ≥ 3 identical values within 2 % of the extreme).
/// @param flat_threshold [unit of x] smallest peak-to-peak accepted
DspStatus check_waveform(const double* x, std::size_t n, double flat_threshold);

}  // namespace model::dsp
