#pragma once
// The vibration analyst's signal toolkit (time and angle domain), all transforms
// through kissfft (fft.hpp):
//  - waveform statistics: RMS, peak, crest factor, kurtosis;
//  - Hann amplitude spectra of any length, tone amplitudes by main-lobe energy and
//    the local noise floor (median of the neighbouring lines);
//  - band-limited analytic signals and squared envelopes (ideal FFT-domain filters);
//  - cepstral prewhitening (CPW: Sawalhi, Randall & Endo, MSSP 21 (2007); Borghesani
//    et al., MSSP 36 (2013)), which Smith & Randall (MSSP 64–65 (2015), the CWRU
//    benchmark) found the most reliable first step of envelope analysis;
//  - the real cepstrum;
//  - the kurtogram: spectral kurtosis of the complex envelope of every band of a
//    1/3-binary tree (Antoni, MSSP 21 (2007) "Fast computation of the kurtogram"),
//    here with ideal (FFT-domain) band filters instead of Antoni's quasi-analytic FIR
//    bank, which gives the same band layout with exact band edges.
//
// Thread context: host tools and the diagnosis's low-priority thread; these
// functions allocate their work buffers (never call them on the real-time thread).

#include <cstddef>
#include <vector>

#include "model/diagnosis/fft.hpp"

namespace model::diagnosis {

struct WaveformStatistics {
  double mean = 0.0;          // [unit of x]
  double rms = 0.0;           // [unit of x] about the mean
  double peak = 0.0;          // [unit of x] max |x − mean|
  double crest_factor = 0.0;  // [-] peak / rms (√2 for a sine)
  double kurtosis = 0.0;      // [-] E[(x−μ)⁴]/σ⁴ (3 for Gaussian noise, 1.5 for a sine)
};

/// Statistics of x[0..n); all zero for n = 0 or a constant x.
WaveformStatistics statistics(const double* x, std::size_t n);

/// Hann-windowed single-sided amplitude spectrum of x[0..n) (mean removed, scaled by
/// 2/Σw so that a sine of amplitude A centred on a line reads A). out: n/2 + 1 lines,
/// line k at k/n cycles per sample. `fft` must have size n.
void hann_amplitude_spectrum(const double* x, std::size_t n, const Fft& fft,
                             std::vector<double>& out);

/// Hann equivalent noise bandwidth [lines] (Harris 1978).
inline constexpr double kHannEnbw = 1.5;

/// Amplitude of a sinusoid near fractional line `line` of a Hann amplitude spectrum, from
/// the energy of the lines within ±half_width of it: sqrt(Σ a_k² / ENBW) (no scalloping).
double lobe_amplitude(const std::vector<double>& spectrum, double line, std::size_t half_width = 2);

/// What noise alone reads as lobe_amplitude() near `line`: the median of the lines within
/// ±reach of it, outside ±(half_width + 1), scaled by sqrt((2·half_width+1)/ENBW).
double lobe_noise_floor(const std::vector<double>& spectrum, double line,
                        std::size_t half_width = 2, std::size_t reach = 24);

/// Analytic signal of x band-passed to [f_lo, f_hi) by an ideal filter (FFT of length
/// fft_size_at_least(n), zero-padded): out[i] for i < n, whose modulus is the band's envelope.
/// Frequencies in Hz with fs_hz the sample rate.
std::vector<Complex> band_analytic(const double* x, std::size_t n, double fs_hz, double f_lo_hz,
                                   double f_hi_hz);

/// Squared envelope |band_analytic|² of x in [f_lo, f_hi).
std::vector<double> squared_envelope(const double* x, std::size_t n, double fs_hz, double f_lo_hz,
                                     double f_hi_hz);

/// Share of the record tapered at each end before cepstral prewhitening (Tukey).
inline constexpr double kCpwTaper = 0.02;

/// Cepstral prewhitening: x_w = IFFT(X/|X|) over a zero-padded FFT, truncated to n
/// samples: the real cepstrum set to zero at every quefrency but zero, i.e. the spectral
/// envelope (all deterministic lines and resonances) flattened, the phase kept. x is
/// first tapered over kCpwTaper of its length at each end (see signal.cpp); analyse the
/// result away from its ends.
std::vector<double> cepstral_prewhiten(const double* x, std::size_t n);

/// The linear filter cepstral prewhitening applies to one record (1/|X| per bin), kept so
/// that another record — a simulation, at another rate and length — can be passed through
/// the same filter and compared with it like with like. Stored as the record's periodogram
/// P(f) = |X(f)|²/(fs·n) (tapered as cepstral_prewhiten tapers), as running sums over its
/// FFT bins (bin j covers [(j − ½)·bin_hz, (j + ½)·bin_hz)).
struct WhiteningReference {
  double bin_hz = 0.0;
  std::vector<double> cumulative;  // Σ_{j<k} P_j·bin_hz, k = 0..bins
  bool valid() const { return bin_hz > 0.0 && cumulative.size() > 1; }
  /// Mean of P over [f_lo, f_hi) (the bin containing f_lo when the interval is narrower);
  /// 0 outside the record's band.
  double mean_psd(double f_lo_hz, double f_hi_hz) const;
};

/// cepstral_prewhiten that also returns the filter it applied as `reference`.
std::vector<double> cepstral_prewhiten(const double* x, std::size_t n, double fs_hz,
                                       WhiteningReference& reference);

/// x through another record's prewhitening filter: X_k / √(P_ref(f_k)·fs·n) with P_ref
/// averaged over x's own bin, so that a record with the reference's spectrum comes out with
/// unit bin magnitudes as cepstral_prewhiten gives it, and one with weaker or stronger
/// content at some frequency comes out weaker or stronger there (a noise-free simulation
/// prewhitened by itself would have every bin of its numerical floor raised to unity).
/// Tapered and truncated as cepstral_prewhiten; zero where the reference has no power.
std::vector<double> whiten_like(const double* x, std::size_t n, double fs_hz,
                                const WhiteningReference& reference);

/// Real cepstrum c[q] = IFFT(ln|X|)[q], q = 0..n−1 in samples (of the time or angle
/// domain of x); |X| is floored at 1e-12 of its largest value. A family of lines spaced
/// by Δ lines of an n-point spectrum shows as a peak at quefrency n/Δ (rahmonics).
std::vector<double> real_cepstrum(const double* x, std::size_t n);

/// One band of a kurtogram.
struct KurtogramBand {
  double level = 0.0;     // [-] log2 of (fs/2)/bandwidth: 0, 1, 1.6, 2, 2.6, ...
  double f_lo_hz = 0.0;   // [Hz]
  double f_hi_hz = 0.0;   // [Hz]
  double kurtosis = 0.0;  // [-] spectral kurtosis E|c|⁴/(E|c|²)² − 2 of the complex envelope
};

struct KurtogramConfig {
  int max_level = 7;            // [-] finest level (bands (fs/2)/2^max_level wide)
  double min_bandwidth_hz = 0;  // [Hz] bands narrower than this are not computed
  double min_frequency_hz = 0;  // [Hz] bands starting below this are not candidates for best
};

struct Kurtogram {
  std::vector<KurtogramBand> bands;  // every band computed, level by level
  KurtogramBand best;                // the band of highest spectral kurtosis (a candidate)
};

/// Kurtogram of x (fs_hz): for every level l = 0..max_level the 2^l bands of width
/// (fs/2)/2^l and for l ≥ 1 the 3·2^(l−1) bands of width (fs/2)/(3·2^(l−1)); the complex
/// envelope of each band is the inverse FFT of that band's lines alone (decimated).
/// Gaussian noise gives ≈ 0, a steady sine −1, a train of impulses exciting a resonance
/// a large positive value.
Kurtogram kurtogram(const double* x, std::size_t n, double fs_hz, const KurtogramConfig& config);

/// Ideal low-pass: the lines of x above cutoff_hz set to zero (zero-padded FFT).
std::vector<double> lowpass(const double* x, std::size_t n, double fs_hz, double cutoff_hz);

}  // namespace model::diagnosis
