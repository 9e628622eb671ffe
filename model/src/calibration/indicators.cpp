#include "model/calibration/indicators.hpp"

#include <algorithm>
#include <cmath>

namespace model::calibration {

Indicators compute_indicators(const dsp::PointFeatures& sim, const dsp::PointFeatures& meas) {
  Indicators out;
  out.valid = true;
  // f1 (our definition, see header): relative RMS error.
  if (meas.rms > 0.0 && std::isfinite(sim.rms)) {
    out.f1 = std::abs(sim.rms - meas.rms) / meas.rms;
  } else {
    out.f1 = kIndicatorPenalty;
    out.valid = false;
  }
  const std::size_t count = meas.count;
  out.tones = meas.resolved_count();
  if (sim.count != count || out.tones < kMinTones) {
    out.f2 = out.f3 = kIndicatorPenalty;
    out.valid = false;
    return out;
  }
  const auto n = static_cast<double>(out.tones);
  // f3: MAPE over the resolved tones (resolved implies A_m > 0).
  double mean_s = 0.0;
  double mean_m = 0.0;
  double ape = 0.0;
  for (std::size_t i = 0; i < count; ++i) {
    if (!meas.resolved[i]) continue;
    mean_s += sim.amplitude[i];
    mean_m += meas.amplitude[i];
    ape += std::abs(sim.amplitude[i] - meas.amplitude[i]) / meas.amplitude[i];
  }
  out.f3 = std::min(ape / n, kIndicatorPenalty);
  // f2: 1 − Pearson ρ.
  mean_s /= n;
  mean_m /= n;
  double sxy = 0.0;
  double sxx = 0.0;
  double syy = 0.0;
  for (std::size_t i = 0; i < count; ++i) {
    if (!meas.resolved[i]) continue;
    const double dx = sim.amplitude[i] - mean_s;
    const double dy = meas.amplitude[i] - mean_m;
    sxy += dx * dy;
    sxx += dx * dx;
    syy += dy * dy;
  }
  if (sxx > 0.0 && syy > 0.0 && std::isfinite(sxy)) {
    out.f2 = 1.0 - sxy / std::sqrt(sxx * syy);
  } else {
    out.f2 = kIndicatorPenalty;
    out.valid = false;
  }
  if (!std::isfinite(out.f1)) out.f1 = kIndicatorPenalty;
  if (!std::isfinite(out.f3)) out.f3 = kIndicatorPenalty;
  return out;
}

bool within_thresholds(const Indicators& i) {
  return i.valid && i.f1 <= kF1Threshold && i.f2 <= kF2Threshold && i.f3 <= kF3Threshold;
}

double worst_threshold_ratio(const Indicators& i) {
  return std::max({i.f1 / kF1Threshold, i.f2 / kF2Threshold, i.f3 / kF3Threshold});
}

}  // namespace model::calibration
