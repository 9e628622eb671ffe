#include "recording/mesh_lines.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "model/dsp/spectrum.hpp"

namespace app::recording {
namespace {

constexpr std::size_t kMaxFft = 65536;  // [samples] spectrum block for the mesh-line check
constexpr double kLineWindow = 0.015;   // [-] ± relative half-width searched for a line
constexpr double kBandLow = 0.8;        // [-] background band around a line, × f
constexpr double kBandHigh = 1.25;      // [-]
constexpr double kScaleMin = 0.2;       // [-] scale search range
constexpr double kScaleMax = 5.0;       // [-]
constexpr double kScaleStep = 1.01;     // [-] geometric step (< 2·kLineWindow: no gaps)
constexpr double kMaxProminence = 1e6;  // [-] cap (a line over an all-zero band)
constexpr int kHarmonics = 3;           // mesh harmonics in a line family

/// Peak / local median of the amplitude spectrum near f; 0 when f is not resolvable, 1
/// when the window's peak is not the strongest line of the band around it.
double prominence(const std::vector<double>& spec, double df, double f_hz, double nyquist_hz) {
  const double lo_hz = f_hz * (1.0 - kLineWindow), hi_hz = f_hz * (1.0 + kLineWindow);
  if (!(f_hz * kLineWindow >= df) || f_hz * kBandHigh >= 0.9 * nyquist_hz) return 0.0;
  const auto line = [&](double hz) { return static_cast<std::size_t>(std::lround(hz / df)); };
  const std::size_t w0 = line(lo_hz), w1 = line(hi_hz);
  const std::size_t b0 = std::max<std::size_t>(1, line(f_hz * kBandLow));
  const std::size_t b1 = std::min(spec.size() - 1, line(f_hz * kBandHigh));
  double peak = 0.0;
  for (std::size_t k = w0; k <= w1 && k < spec.size(); ++k) peak = std::max(peak, spec[k]);
  std::vector<double> band;
  band.reserve(b1 - b0 + 1);
  for (std::size_t k = b0; k <= b1; ++k) {
    if (k < w0 || k > w1) band.push_back(spec[k]);
  }
  if (band.size() < 8) return 0.0;
  // A mesh line dominates its band (sidebands, other lines): in a dense spectrum some
  // line always falls in a ±1.5 % window, but not the band's strongest.
  if (*std::max_element(band.begin(), band.end()) > peak) return 1.0;
  auto mid = band.begin() + static_cast<std::ptrdiff_t>(band.size() / 2);
  std::nth_element(band.begin(), mid, band.end());
  return *mid > 0.0 ? std::min(peak / *mid, kMaxProminence) : (peak > 0.0 ? kMaxProminence : 0.0);
}

struct ScaleScore {
  std::size_t fundamentals = 0;  // stages whose mesh fundamental stands out
  std::size_t lines = 0;         // lines of the family (harmonics 1..kHarmonics) that do
  double score = 0.0;            // Σ log(prominence) over those lines
  std::size_t checked = 0;       // stages whose fundamental is resolvable
  double best = 0.0;
  bool better_than(const ScaleScore& o) const {
    if (fundamentals != o.fundamentals) return fundamentals > o.fundamentals;
    return lines > o.lines || (lines == o.lines && score > o.score);
  }
};

/// Amplitude spectra of the acceleration channels, one block each.
struct Spectra {
  std::vector<std::vector<double>> spec;
  double df = 0.0;
  double nyquist = 0.0;
};

/// The mesh-line family at scale s: harmonics 1..kHarmonics of every stage's mesh
/// frequency, a line counted when it stands out in any channel. A real family shows its
/// harmonics; a coincidence in a dense spectrum does not.
ScaleScore score_at(const Spectra& sp, double s, const std::vector<double>& expected_hz) {
  ScaleScore out;
  for (double f : expected_hz) {
    for (int h = 1; h <= kHarmonics; ++h) {
      double p = 0.0;
      for (const auto& spec : sp.spec)
        p = std::max(p, prominence(spec, sp.df, s * h * f, sp.nyquist));
      if (p <= 0.0) continue;
      if (h == 1) ++out.checked;
      out.best = std::max(out.best, p);
      if (p >= kLineProminence) {
        ++out.lines;
        if (h == 1) ++out.fundamentals;
        out.score += std::log(p);
      }
    }
  }
  return out;
}

/// The best score within ±2 % of s (the scan's grid around it).
std::pair<double, ScaleScore> best_near(const Spectra& sp, double s,
                                        const std::vector<double>& expected_hz) {
  std::pair<double, ScaleScore> best{s, score_at(sp, s, expected_hz)};
  for (double k :
       {1.0 / kScaleStep / kScaleStep, 1.0 / kScaleStep, kScaleStep, kScaleStep * kScaleStep}) {
    const ScaleScore c = score_at(sp, s * k, expected_hz);
    if (c.better_than(best.second)) best = {s * k, c};
  }
  return best;
}

}  // namespace

MeshLineScale find_mesh_line_scale(const std::vector<const std::vector<double>*>& channels,
                                   double fs_hz, const std::vector<double>& expected_hz,
                                   double hint_scale) {
  MeshLineScale out;
  std::size_t n = kMaxFft;
  for (const auto* x : channels) {
    while (n > x->size()) n /= 2;
  }
  if (channels.empty() || n < kMinMeshSamples || !(fs_hz > 0.0)) return out;
  model::dsp::SpectrumAnalyzer analyzer(n);
  Spectra sp;
  sp.df = fs_hz / static_cast<double>(n);
  sp.nyquist = 0.5 * fs_hz;
  for (const auto* x : channels) {
    sp.spec.emplace_back(analyzer.lines());
    analyzer.amplitude_spectrum(x->data() + (x->size() - n), sp.spec.back().data());  // last block
  }

  out.checked = score_at(sp, 1.0, expected_hz).checked;
  // 1. Where the metadata puts them: kept when a stage's mesh fundamental stands out there.
  //    (Conservative: a sample rate declared m times too low, which puts the true m-th
  //    harmonics there, passes this check; the tacho check catches it.)
  std::pair<double, ScaleScore> best = best_near(sp, 1.0, expected_hz);
  // 2. Where the tacho puts them.
  if (best.second.fundamentals == 0 && hint_scale > 0.0)
    best = best_near(sp, hint_scale, expected_hz);
  if (best.second.fundamentals == 0) {
    // 3. Anywhere in [0.2, 5], only a convincing family counts — two stages' fundamentals,
    //    or one with two of its harmonics — since some line of a rich spectrum stands out
    //    at almost any single frequency.
    best = {1.0, {}};
    for (double s = kScaleMin; s <= kScaleMax; s *= kScaleStep) {
      const ScaleScore c = score_at(sp, s, expected_hz);
      if (c.better_than(best.second)) best = {s, c};
    }
    if (best.second.fundamentals < 2 && !(best.second.fundamentals == 1 && best.second.lines >= 3))
      return out;
  }
  double best_s = best.first;
  // Refine: the energy-weighted centroid of ±2 lines around the most prominent
  // fundamental's peak.
  double best_p = 0.0, refined = best_s;
  for (double f : expected_hz) {
    for (const auto& spec : sp.spec) {
      const double p = prominence(spec, sp.df, best_s * f, sp.nyquist);
      if (p < kLineProminence || p <= best_p) continue;
      const auto k0 =
          static_cast<std::size_t>(std::lround(best_s * f * (1.0 - kLineWindow) / sp.df));
      const auto k1 =
          static_cast<std::size_t>(std::lround(best_s * f * (1.0 + kLineWindow) / sp.df));
      std::size_t peak = k0;
      for (std::size_t k = k0; k <= k1 && k < spec.size(); ++k) {
        if (spec[k] > spec[peak]) peak = k;
      }
      double e = 0.0, ek = 0.0;
      for (std::size_t k = peak - std::min<std::size_t>(peak, 2); k <= peak + 2 && k < spec.size();
           ++k) {
        e += spec[k] * spec[k];
        ek += spec[k] * spec[k] * static_cast<double>(k);
      }
      if (e > 0.0) {
        best_p = p;
        refined = ek / e * sp.df / f;
      }
    }
  }
  out.scale = refined;
  if (hint_scale > 0.0)
    out.hint_fundamentals = best_near(sp, hint_scale, expected_hz).second.fundamentals;
  out.lines = best.second.lines;
  out.prominence = best.second.best;
  return out;
}

}  // namespace app::recording
