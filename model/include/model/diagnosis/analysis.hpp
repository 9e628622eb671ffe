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
  std::vector<ShaftAverage> averages;
  double max_order = 0.0;  // [orders] max_frequency_hz at the window's mean speed
};

/// Samples per reference revolution for a sample rate: the smallest power of two at
/// which the angle-domain rate is at least fs at the slowest speed (no aliasing).
std::size_t samples_per_rev_for(double fs_hz, double slowest_ref_hz);

/// Analyses x (n samples at fs_hz) over `window` of `map` (the reference shaft's angle).
/// `band`: the envelope band to use (a simulated channel takes its recording's); nullptr:
/// choose it by the kurtogram. `envelope_max_order`: highest order the envelope spectrum
/// must cover. Returns false when the window does not fit in x.
bool analyse_channel(const double* x, std::size_t n, double fs_hz, const AngleMap& map,
                     const AnalysisWindow& window, const Catalogue& catalogue,
                     const AnalysisConfig& config, double envelope_max_order,
                     const KurtogramBand* band, ChannelAnalysis& out);

/// Highest envelope-line order of the catalogue (with its tolerance).
double envelope_max_order(const Catalogue& catalogue);

}  // namespace model::diagnosis
