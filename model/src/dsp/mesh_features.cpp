#include "model/dsp/mesh_features.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace model::dsp {

namespace {

// Known lines closer than this [lines] are one line (e.g. a shaft harmonic that is also a
// mesh harmonic): fitted once.
constexpr double kSameLine = 0.25;

DspStatus validate(const FeatureConfig& c, const SpectrumAnalyzer& analyzer) {
  if (!analyzer.valid() || c.mesh_count == 0 || c.mesh_count > kMaxMeshes || c.harmonics == 0 ||
      c.harmonics > kMaxHarmonics || c.revolutions < 2 || c.lobe_half_width < 2 ||
      c.shaft_count > kMaxShafts || !(c.max_variance_inflation > 1.0)) {
    return DspStatus::kBadConfig;
  }
  const double nyquist_order = 0.5 * static_cast<double>(c.samples_per_rev);
  const double lobe_orders =
      static_cast<double>(c.lobe_half_width + 1) / static_cast<double>(c.revolutions);
  for (std::size_t m = 0; m < c.mesh_count; ++m) {
    for (std::size_t h = 1; h <= c.harmonics; ++h) {
      const double order = static_cast<double>(h) * c.mesh_orders[m];
      if (!(order > 0.0) || order + lobe_orders >= nyquist_order) return DspStatus::kBadConfig;
      if (order < lobe_orders) return DspStatus::kTooShort;
    }
  }
  return DspStatus::kOk;
}

struct Line {
  double position = 0.0;  // [lines] order × revolutions
  int tone = -1;          // compared tone index, −1 for a known line that is only fitted
};

}  // namespace

FeatureExtractor::FeatureExtractor(const FeatureConfig& config)
    : config_(config),
      analyzer_(config.samples_per_rev * config.revolutions),
      tracker_(config.samples_per_rev, config.revolutions, config.max_pulses) {
  config_status_ = validate(config_, analyzer_);
  if (config_status_ == DspStatus::kBadConfig) return;
  angle_.resize(analyzer_.size());
  spectrum_.resize(analyzer_.lines());
  excluded_.assign(analyzer_.lines(), 0);
  if (config_status_ == DspStatus::kOk) build_fit();
}

void FeatureExtractor::build_fit() {
  const auto revs = static_cast<double>(config_.revolutions);
  const auto half = static_cast<int>(config_.lobe_half_width);
  const int last =
      static_cast<int>(analyzer_.lines()) - 2;  // highest complex line (Nyquist excluded)
  // Every line: the compared tones first, then the known lines fitted with them.
  std::vector<Line> lines;
  for (std::size_t m = 0; m < config_.mesh_count; ++m) {
    for (std::size_t h = 1; h <= config_.harmonics; ++h) {
      lines.push_back({static_cast<double>(h) * config_.mesh_orders[m] * revs,
                       static_cast<int>(m * config_.harmonics + (h - 1))});
    }
  }
  // A known line on top of a compared tone (closer than kSameLine) cannot be told apart
  // from it at any resolution: the tone is marked inseparable (infinite inflation).
  std::array<bool, kMaxAmplitudes> covered{};
  auto add_known = [&](double position) {
    if (position < half + 1 || position > last - half) return;  // no room for its lobe
    for (const Line& l : lines) {
      if (std::abs(l.position - position) < kSameLine) {
        if (l.tone >= 0) covered[static_cast<std::size_t>(l.tone)] = true;
        return;
      }
    }
    lines.push_back({position, -1});
  };
  for (std::size_t m = 0; m < config_.mesh_count; ++m) {
    for (std::size_t h = config_.harmonics + 1;
         h <= config_.harmonics + config_.extra_mesh_harmonics; ++h)
      add_known(static_cast<double>(h) * config_.mesh_orders[m] * revs);
  }
  for (std::size_t s = 0; s < config_.shaft_count; ++s) {
    for (std::size_t h = 1; h <= config_.shaft_harmonics; ++h)
      add_known(static_cast<double>(h) * config_.shaft_orders[s] * revs);
  }
  // Rows: every line within ±half of a line; excluded_ marks them for the noise floor.
  std::fill(excluded_.begin(), excluded_.end(), 0);
  for (const Line& l : lines) {
    const auto c = static_cast<int>(std::lround(l.position));
    for (int k = c - half; k <= c + half; ++k) {
      if (k >= 1 && k <= last && !excluded_[static_cast<std::size_t>(k)]) {
        excluded_[static_cast<std::size_t>(k)] = 1;
        fit_bins_.push_back(k);
      }
    }
  }
  std::sort(fit_bins_.begin(), fit_bins_.end());
  // G (rows × lines): the window's kernel of each line at each row; the normal matrix's
  // inverse gives the pseudo-inverse (GᴴG)⁻¹Gᴴ and each tone's variance inflation
  // [(GᴴG)⁻¹]_ii·(GᴴG)_ii. Lines that share no row are independent (block structure).
  const auto rows = static_cast<Eigen::Index>(fit_bins_.size());
  const auto cols = static_cast<Eigen::Index>(lines.size());
  Eigen::MatrixXcd g(rows, cols);
  for (Eigen::Index r = 0; r < rows; ++r) {
    for (Eigen::Index j = 0; j < cols; ++j) {
      const double delta =
          lines[static_cast<std::size_t>(j)].position - fit_bins_[static_cast<std::size_t>(r)];
      g(r, j) =
          std::abs(delta) <= 8.0 ? analyzer_.window_kernel(delta) : std::complex<double>(0.0, 0.0);
    }
  }
  const Eigen::MatrixXcd normal = g.adjoint() * g;
  const Eigen::MatrixXcd inverse = normal.completeOrthogonalDecomposition().pseudoInverse();
  const Eigen::MatrixXcd pinv = inverse * g.adjoint();
  for (Eigen::Index j = 0; j < cols; ++j) {
    const int tone = lines[static_cast<std::size_t>(j)].tone;
    if (tone < 0) continue;
    const auto t = static_cast<std::size_t>(tone);
    fit_[t].assign(static_cast<std::size_t>(rows), {0.0, 0.0});
    for (Eigen::Index r = 0; r < rows; ++r) fit_[t][static_cast<std::size_t>(r)] = pinv(j, r);
    fit_norm_[t] = pinv.row(j).norm();
    inflation_[t] = std::abs(inverse(j, j)) * std::abs(normal(j, j));
    if (!std::isfinite(inflation_[t]) || covered[t]) inflation_[t] = 1e300;
  }
  // Two compared tones that cannot be separated: the resolution is too coarse.
  for (std::size_t a = 0; a < lines.size(); ++a) {
    for (std::size_t b = a + 1; b < lines.size(); ++b) {
      if (lines[a].tone < 0 || lines[b].tone < 0) continue;
      if (std::abs(lines[a].position - lines[b].position) < 2.0 * half &&
          (inflation_[static_cast<std::size_t>(lines[a].tone)] > config_.max_variance_inflation ||
           inflation_[static_cast<std::size_t>(lines[b].tone)] > config_.max_variance_inflation)) {
        config_status_ = DspStatus::kTooShort;
      }
    }
  }
}

double FeatureExtractor::required_duration_s(double shaft_hz) const {
  return static_cast<double>(config_.revolutions + 1) / shaft_hz;
}

DspStatus FeatureExtractor::extract(const double* x, std::size_t n, double fs_hz,
                                    const SpeedReference& speed, PointFeatures& out) {
  if (config_status_ != DspStatus::kOk) return config_status_;
  const DspStatus quality = check_waveform(x, n, config_.flat_threshold);
  if (quality != DspStatus::kOk) return quality;
  const DspStatus tracked = tracker_.resample(x, n, fs_hz, speed, angle_.data());
  if (tracked != DspStatus::kOk) return tracked;
  analyzer_.amplitude_spectrum(angle_.data(), spectrum_.data());
  const std::complex<double>* spectrum = analyzer_.complex_spectrum();
  const double lines_per_order = static_cast<double>(config_.revolutions);
  out.rms = rms(x, n);
  out.count = config_.mesh_count * config_.harmonics;
  const auto lines = static_cast<long long>(analyzer_.lines());
  const auto reach =
      static_cast<long long>(std::min<std::size_t>(config_.noise_half_width, kMaxNoiseLines / 2));
  // amplitude_spectrum() scales |X| by 2/Σw; back to |X| for the noise floor.
  const double raw_per_amplitude = 0.25 * static_cast<double>(analyzer_.size());
  for (std::size_t i = 0; i < out.count; ++i) {
    const std::size_t m = i / config_.harmonics;
    const std::size_t h = i % config_.harmonics + 1;
    std::complex<double> c(0.0, 0.0);
    const std::vector<std::complex<double>>& row = fit_[i];
    for (std::size_t r = 0; r < row.size(); ++r) {
      if (row[r] != std::complex<double>(0.0, 0.0))
        c += row[r] * spectrum[static_cast<std::size_t>(fit_bins_[r])];
    }
    out.amplitude[i] = 2.0 * std::abs(c);
    out.phase[i] = std::arg(c);
    // Noise floor: with noise of E|X(k)|² = s² on the fitted lines, E|c|² = s²·‖row‖²; s from
    // the median of the neighbouring lines outside every known lobe (Rayleigh: median = s·√ln2).
    const double line = static_cast<double>(h) * config_.mesh_orders[m] * lines_per_order;
    const long long centre = std::llround(line);
    std::size_t k = 0;
    for (long long j = centre - reach; j <= centre + reach; ++j) {
      if (j < 1 || j >= lines - 1 || excluded_[static_cast<std::size_t>(j)]) continue;
      neighbours_[k++] = spectrum_[static_cast<std::size_t>(j)];
    }
    double floor = 0.0;
    if (k > 0) {
      std::nth_element(neighbours_.begin(), neighbours_.begin() + static_cast<long>(k / 2),
                       neighbours_.begin() + static_cast<long>(k));
      const double s = neighbours_[k / 2] * raw_per_amplitude / std::sqrt(std::log(2.0));
      floor = 2.0 * s * fit_norm_[i];
    }
    out.noise_floor[i] = floor;
    out.separable[i] = inflation_[i] <= config_.max_variance_inflation;
    out.resolved[i] = out.separable[i] && out.amplitude[i] > 0.0 &&
                      out.amplitude[i] >= config_.resolved_ratio * floor;
  }
  return DspStatus::kOk;
}

}  // namespace model::dsp
