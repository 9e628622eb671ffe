#pragma once
// Locate and name: what is left between a recording and its calibrated simulation,
// expressed as residual features (channel, band, frequencies, the kinematic family that
// explains them), and every hypothesis of the catalogue ranked by how much of it it
// explains.
//
// Line excess. At an order o of a channel, with m the recording's tone amplitude (Hann
// main-lobe energy), s the simulation's and n the recording's local noise floor (what
// noise alone reads there, the median of the neighbouring lines):
//   excess  e = m² − s² − n²            (energy the simulation and the noise leave unexplained)
//   significant when m ≥ snr_min·n and m² ≥ excess_ratio·(s² + n²).
// A hypothesis is scored only when its significant lines add up to min_evidence.
// Bearing lines may lie within ±slip of nominal: the strongest position is taken, but
// never one on a harmonic of a mesh (envelope_exclusions()), and no envelope peak there
// is counted.
//
// Residual features. Every significant excess peak of a channel's order spectrum (up to
// the analysis band) and envelope spectrum is found; the families of the catalogue then
// claim them greedily — the family that explains the most excess energy first — and each
// claim is one feature; peaks no family claims stay as "unexplained" features. A band in
// which the lines the simulation does have are stronger in the recording along the
// transmissibility curve of one resonator (by ≥ gain_db at its peak; see band_features in
// locate.cpp) is a band feature ("amplified in one band"). A shaft whose synchronous-average
// difference signal is impulsive (kurtosis above `impulsive_kurtosis` and above the simulation's)
// is a feature of the synchronous-average domain.
//
// Ranking. Over its significant lines (all points) a hypothesis has the strength
//   strength = Σ w·ln(m² / (s² + n²))          (how far above what is explained they stand)
// and explains, of the significant excess on the lines of its broad family (the same
// modulation at every sideband order, or the shaft's harmonics) and its own, the share
//   share = Σ_its lines w·e / Σ_family lines e;
// it is present to the degree presence = Σ w·[significant] / Σ w (at its best point). Its
// score is share·√presence·strength: the narrow eccentricity family wins over the broad
// crack family when only first sidebands are there (equal share, higher presence), the
// crack when the higher sidebands are there too (the eccentricity's share drops), and
// misfit elsewhere in the spectrum (a foreign gearbox's mesh harmonics) changes neither.
// A tooth crack's score is multiplied by 1 + its shaft's impulsiveness evidence; a
// housing resonance scores the resonance fit's share × its amplification strength.
// Scores rank what to model; the reported confidence comes from the refit (diagnoser.hpp).
//
// Thread context: host tools and the diagnosis's low-priority thread; allocates.

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "model/diagnosis/analysis.hpp"
#include "model/diagnosis/signatures.hpp"

namespace model::diagnosis {

inline constexpr std::size_t kNoFamily = std::numeric_limits<std::size_t>::max();

struct LocateConfig {
  // [-] recording line / noise floor (12 dB): Gaussian noise alone reads above it on
  // fewer than 1 in 10⁵ lobes (lobe energy over 5 Hann lines).
  double snr_min = 4.0;
  // [-] a hypothesis needs Σ w·(m/n)² ≥ this over its significant lines: one clear line
  // (m/n ≥ 5.7) or two at the threshold, never one chance peak.
  double min_evidence = 32.0;
  double excess_ratio = 2.0;        // [-] m² ≥ ratio·(s² + n²): 3 dB above what is explained
  double gain_db = 6.0;             // [dB] band amplification over the channel's median gain
  double impulsive_kurtosis = 4.0;  // [-] difference-signal kurtosis (Gaussian: 3)
  std::size_t max_peaks_per_feature = 8;
  std::size_t min_order_lines = 3;  // [lines] lowest order considered: 3/R
};

/// One channel of the recording and the same channel simulated.
struct ChannelPair {
  std::string channel;   // "point1"
  std::string location;  // bearing id of the sensor, "b5"
  const ChannelAnalysis* recorded = nullptr;
  const ChannelAnalysis* simulated = nullptr;
};

enum class FeatureDomain : unsigned char { kSpectrum, kEnvelope, kAverage, kBand };

struct ResidualFeature {
  std::size_t channel = 0;  // index into the ChannelPair list
  FeatureDomain domain = FeatureDomain::kSpectrum;
  double band_lo_hz = 0.0;       // [Hz]
  double band_hi_hz = 0.0;       // [Hz]
  std::vector<double> peaks_hz;  // [Hz] strongest lines, descending excess
  std::size_t family = kNoFamily;
  std::string shaft;          // kAverage: the shaft
  double excess = 0.0;        // [unit²] (envelope: [-]) excess energy of its lines
  double share = 0.0;         // [-] of the channel's significant excess in its domain
  double max_snr = 0.0;       // [-] strongest line / noise floor
  double gain_db = 0.0;       // kBand: mean amplification [dB]; kAverage: kurtosis
  double resonance_hz = 0.0;  // kBand: the fitted resonance
  double resonance_damping = 0.0;
  double fit_share = 0.0;  // kBand: share of the gains' squared deviation the resonance explains
  double strength = 0.0;   // kBand: Σ ln of the amplification over its lines
};

struct LineMeasure {
  double order = 0.0;      // [orders] where it was read
  double measured = 0.0;   // m
  double simulated = 0.0;  // s
  double noise = 0.0;      // n
  double excess = 0.0;     // e (≥ 0)
  bool significant = false;
};

/// Reads the line at `order` (± tolerance relative) of a recorded and a simulated spectrum.
/// Positions within 2 lines of an order in `exclude` are not taken when searching within
/// the tolerance (envelope spectra: a gearbox's mesh modulation is synchronous, a bearing's
/// is not).
LineMeasure measure_line(const OrderSpectrum& recorded, const OrderSpectrum& simulated,
                         double order, double tolerance, const LocateConfig& config,
                         const std::vector<double>* exclude = nullptr);

/// Shafts at least this fast (in reference orders) have their harmonics excluded from
/// bearing lines: their spacing is wide enough that ±2 lines around each leave a bearing's
/// ±slip window almost whole, and an impact once per revolution (a cracked tooth) puts its
/// envelope lines there.
inline constexpr double kSynchronousShaftOrder = 0.2;

/// [orders] the top of the synchronous comb excluded from bearing lines: above every bearing
/// line of a description like paper-2mw's (3·BPFI + 2 shaft orders ≈ 30 hss orders).
inline constexpr double kSynchronousTopOrder = 60.0;

/// The synchronous orders of the envelope: the harmonics of every mesh (at least 8, and all
/// up to kSynchronousTopOrder) and of every shaft of at least kSynchronousShaftOrder (up to
/// kSynchronousTopOrder). No bearing line is
/// read there (a defect line that falls exactly on one cannot be told from mesh modulation
/// or a once-per-revolution impact).
std::vector<double> envelope_exclusions(const Catalogue& catalogue);

/// Where no bearing line is read in the waveform's order spectrum: the envelope's
/// synchronous comb and every line of a gear or shaft family of the catalogue (mesh
/// harmonics and their sidebands, shaft harmonics, planet pass).
std::vector<double> spectrum_exclusions(const Catalogue& catalogue);

/// The exclusions of a hypothesis's lines: `sync` (envelope_exclusions()) in the envelope,
/// `gears` (spectrum_exclusions()) for a bearing's lines in the spectrum, none otherwise.
const std::vector<double>* bearing_exclusions(const Hypothesis& h, const std::vector<double>& sync,
                                              const std::vector<double>& gears);

struct HypothesisScore {
  std::size_t hypothesis = 0;  // index into Catalogue::hypotheses
  double share = 0.0;
  double presence = 0.0;
  double score = 0.0;
  double evidence = 0.0;  // [-] Σ w·(m/n)² over its significant lines
  double strength = 0.0;  // [-] Σ w·ln(m²/(s² + n²)) over its significant lines
  std::size_t best_channel = 0;
};

struct LocateResult {
  std::vector<ResidualFeature> features;  // descending share within each domain
  std::vector<HypothesisScore> ranking;   // descending score (only score > 0)
  std::vector<double> spectrum_total;     // per channel: significant spectrum excess
  std::vector<double> envelope_total;     // per channel: significant envelope excess
};

LocateResult locate(const Catalogue& catalogue, const std::vector<ChannelPair>& channels,
                    const LocateConfig& config = {});

/// "sidebands of the high-speed mesh spaced at the hss speed (14.30 Hz)": a feature's
/// signature text at a reference speed.
std::string describe_feature(const Catalogue& catalogue, const ResidualFeature& feature,
                             double reference_hz, const std::vector<ChannelPair>& channels);

}  // namespace model::diagnosis
