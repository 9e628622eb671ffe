#include "model/dsp/mesh_features.hpp"

#include <algorithm>
#include <cmath>

namespace model::dsp {

namespace {
DspStatus validate(const FeatureConfig& c, const SpectrumAnalyzer& analyzer) {
  if (!analyzer.valid() || c.mesh_count == 0 || c.mesh_count > kMaxMeshes || c.harmonics == 0 ||
      c.harmonics > kMaxHarmonics || c.revolutions < 2 || c.lobe_half_width < 2) {
    return DspStatus::kBadConfig;
  }
  const double nyquist_order = 0.5 * static_cast<double>(c.samples_per_rev);
  const double min_separation_orders =
      static_cast<double>(2 * c.lobe_half_width + 1) / static_cast<double>(c.revolutions);
  for (std::size_t m = 0; m < c.mesh_count; ++m) {
    for (std::size_t h = 1; h <= c.harmonics; ++h) {
      const double order = static_cast<double>(h) * c.mesh_orders[m];
      if (!(order > 0.0) || order + min_separation_orders >= nyquist_order)
        return DspStatus::kBadConfig;
      if (order < min_separation_orders) return DspStatus::kTooShort;
      for (std::size_t m2 = 0; m2 < c.mesh_count; ++m2) {
        for (std::size_t h2 = 1; h2 <= c.harmonics; ++h2) {
          if (m2 == m && h2 == h) continue;
          const double other = static_cast<double>(h2) * c.mesh_orders[m2];
          if (std::abs(order - other) < min_separation_orders) return DspStatus::kTooShort;
        }
      }
    }
  }
  return DspStatus::kOk;
}
}  // namespace

FeatureExtractor::FeatureExtractor(const FeatureConfig& config)
    : config_(config),
      analyzer_(config.samples_per_rev * config.revolutions),
      tracker_(config.samples_per_rev, config.revolutions, config.max_pulses) {
  config_status_ = validate(config_, analyzer_);
  if (config_status_ == DspStatus::kBadConfig) return;
  angle_.resize(analyzer_.size());
  spectrum_.resize(analyzer_.lines());
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
  const double lines_per_order = static_cast<double>(config_.revolutions);
  out.rms = rms(x, n);
  out.count = config_.mesh_count * config_.harmonics;
  const auto lines = static_cast<long long>(analyzer_.lines());
  const auto lobe = static_cast<long long>(config_.lobe_half_width);
  const auto reach =
      static_cast<long long>(std::min<std::size_t>(config_.noise_half_width, kMaxNoiseLines / 2));
  const double lobe_gain =
      std::sqrt(static_cast<double>(2 * lobe + 1) / SpectrumAnalyzer::kHannEnbwLines);
  for (std::size_t m = 0; m < config_.mesh_count; ++m) {
    for (std::size_t h = 1; h <= config_.harmonics; ++h) {
      const std::size_t i = m * config_.harmonics + (h - 1);
      const double line = static_cast<double>(h) * config_.mesh_orders[m] * lines_per_order;
      out.amplitude[i] = analyzer_.tone_amplitude(spectrum_.data(), line, config_.lobe_half_width);
      // Noise floor: median of the neighbouring lines outside the main lobe.
      const long long c = std::llround(line);
      std::size_t k = 0;
      for (long long j = c - reach; j <= c + reach; ++j) {
        if (j < 1 || j >= lines || std::abs(j - c) <= lobe + 1) continue;
        neighbours_[k++] = spectrum_[static_cast<std::size_t>(j)];
      }
      double floor = 0.0;
      if (k > 0) {
        std::nth_element(neighbours_.begin(), neighbours_.begin() + static_cast<long>(k / 2),
                         neighbours_.begin() + static_cast<long>(k));
        floor = neighbours_[k / 2] * lobe_gain;
      }
      out.noise_floor[i] = floor;
      out.resolved[i] =
          out.amplitude[i] > 0.0 && out.amplitude[i] >= config_.resolved_ratio * floor;
    }
  }
  return DspStatus::kOk;
}

}  // namespace model::dsp
