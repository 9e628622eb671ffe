#pragma once
// Everything the diagnosis computes from one channel's waveform (recorded or
// simulated), in the angle domain of the reference shaft:
//  - the order spectrum over a window of whole reference revolutions;
//  - the kurtogram of the prewhitened waveform and the band it selects (the band where
//    impacts ring), and the squared-envelope order spectrum in that band, normalised
//    by the mean squared envelope (a modulation spectrum: dimensionless, so a recorded
//    and a simulated channel compare whatever their gains);
//  - the synchronous average of every shaft that carries a gear of a parallel stage,
//    with its residual and difference signals;
//  - the waveform's statistics (RMS, crest factor, kurtosis) and the cepstrum of the
//    order spectrum's log (its rahmonics at the shaft periods).
//
// Thread context: host tools and the diagnosis's low-priority thread; allocates.

#include <cstddef>
#include <string>
#include <vector>

#include "model/diagnosis/angle.hpp"
#include "model/diagnosis/signal.hpp"
#include "model/diagnosis/signatures.hpp"

namespace model::diagnosis {

struct AnalysisConfig {
  double max_frequency_hz =
      5000.0;  // [Hz] band of the order spectrum compared (the contract's residual band)
  double band_max_hz = 0.0;     // [Hz] kurtogram bands must end below this (0: fs/2)
  int kurtogram_max_level = 7;  // [-]
  bool prewhiten = true;        // kurtogram and envelope on the cepstrally prewhitened waveform
  bool synchronous_averages = true;
};

/// A window of the recording in reference-shaft revolutions.
struct AnalysisWindow {
  double start_rev = 0.0;  // [rev] of the angle map
  std::size_t revs = 0;    // [-]
};

struct ShaftAverage {
  std::string shaft;
  double order = 0.0;  // [orders of the reference]
  SynchronousAverage tsa;
};

struct ChannelAnalysis {
  WaveformStatistics stats;  // of the raw waveform within the window
  OrderSpectrum spectrum;    // reference orders, up to max_frequency_hz at least
  Kurtogram kurtogram;       // of the (prewhitened) waveform; empty when a band was given
  KurtogramBand band;        // envelope band used
  OrderSpectrum envelope;    // squared envelope / its mean, reference orders
  // The prewhitening filter of this window (when the kurtogram was run on it): pass a
  // simulation through it (analyse_channel's `whiten_as`) to compare envelopes like with like.
  WhiteningReference whitening;
  std::vector<ShaftAverage> averages;
  double max_order = 0.0;  // [orders] max_frequency_hz at the window's mean speed
};

/// Samples per reference revolution for a sample rate: the smallest power of two at
/// which the angle-domain rate is at least fs at the slowest speed (no aliasing).
std::size_t samples_per_rev_for(double fs_hz, double slowest_ref_hz);

/// Analyses x (n samples at fs_hz) over `window` of `map` (the reference shaft's angle).
/// `band`: the envelope band to use (a simulated channel takes its recording's); nullptr:
/// choose it by the kurtogram. `envelope_max_order`: highest order the envelope spectrum
/// must cover. `whiten_as`: prewhiten x with this (a recording's) filter instead of its own,
/// and normalise its squared envelope as that recording's is normalised — a simulation's
/// envelope then compares with the recording's like with like (without it a noise-free
/// simulation's numerical floor is whitened to unity and masks its impacts). Returns false
/// when the window does not fit in x.
bool analyse_channel(const double* x, std::size_t n, double fs_hz, const AngleMap& map,
                     const AnalysisWindow& window, const Catalogue& catalogue,
                     const AnalysisConfig& config, double envelope_max_order,
                     const KurtogramBand* band, ChannelAnalysis& out,
                     const WhiteningReference* whiten_as = nullptr);

/// Adds to (miss, total) the part of rec's order-spectrum energy over lines 1..last that sim
/// does not explain, compared in power per band: Σ_b (√E_rec,b − √E_sim,b)² and Σ_b E_rec,b,
/// bands 1/12 of an octave wide (at least 8 lines). An impact train with slip is not periodic:
/// above its first harmonics its lines are a continuum whose line-by-line pattern is random,
/// which a model can match in power per band only (line by line, even the true train would
/// add its own pattern to the residual).
void add_band_residual(const OrderSpectrum& rec, const OrderSpectrum& sim, std::size_t last,
                       double& miss, double& total);

/// The same comparison over the given lines of rec (sorted indices), in power over each run
/// of adjacent lines: Σ_run (√E_rec − √E_sim)² and Σ_run E_rec — a window around an envelope
/// line of a train with slip, whose line wanders and broadens by a few lines where a periodic
/// model's stays put.
void add_window_residual(const OrderSpectrum& rec, const OrderSpectrum& sim,
                         const std::vector<std::size_t>& lines, double& miss, double& total);

/// Highest envelope-line order of the catalogue (with its tolerance).
double envelope_max_order(const Catalogue& catalogue);

}  // namespace model::diagnosis
