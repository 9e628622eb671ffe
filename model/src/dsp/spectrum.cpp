#include "model/dsp/spectrum.hpp"

#include <kissfft/kissfft.hh>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

namespace model::dsp {

const char* to_string(DspStatus status) {
  switch (status) {
    case DspStatus::kOk:
      return "ok";
    case DspStatus::kBadConfig:
      return "analysis configured with an impossible size";
    case DspStatus::kTooShort:
      return "recording too short for the frequency resolution the indicators need";
    case DspStatus::kFlat:
      return "channel is flat (no variation)";
    case DspStatus::kClipped:
      return "channel is clipped (flat tops at its extreme values)";
    case DspStatus::kNonFinite:
      return "channel holds non-finite samples";
    case DspStatus::kNoSpeed:
      return "no usable speed reference (tacho, speed or mesh line)";
  }
  return "unknown";
}

namespace {
bool is_power_of_two(std::size_t n) { return n != 0 && (n & (n - 1)) == 0; }
}  // namespace

// The real-input transform of length N runs a complex kissfft of length N/2
// (kissfft::transform_real) into N/2 complex outputs.
struct SpectrumAnalyzer::Plan {
  explicit Plan(std::size_t nfft) : fft(nfft / 2, false), out(nfft / 2) {}
  kissfft<double> fft;
  std::vector<std::complex<double>> out;
};

SpectrumAnalyzer::SpectrumAnalyzer(std::size_t nfft) {
  if (!is_power_of_two(nfft) || nfft < 16 || nfft > kMaxFftSize) return;  // invalid(): nfft_ == 0
  nfft_ = nfft;
  plan_ = std::make_unique<Plan>(nfft);
  window_.resize(nfft);
  windowed_.resize(nfft);
  double sum = 0.0;
  for (std::size_t i = 0; i < nfft; ++i) {
    // Periodic Hann window (Harris 1978): w[n] = 0.5·(1 − cos(2πn/N)).
    window_[i] = 0.5 * (1.0 - std::cos(2.0 * std::numbers::pi * static_cast<double>(i) /
                                       static_cast<double>(nfft)));
    sum += window_[i];
  }
  amplitude_gain_ = 2.0 / sum;
}

SpectrumAnalyzer::~SpectrumAnalyzer() = default;

void SpectrumAnalyzer::amplitude_spectrum(const double* x, double* out) {
  if (!valid()) return;
  double mean = 0.0;
  for (std::size_t i = 0; i < nfft_; ++i) mean += x[i];
  mean /= static_cast<double>(nfft_);
  for (std::size_t i = 0; i < nfft_; ++i) windowed_[i] = (x[i] - mean) * window_[i];
  plan_->fft.transform_real(windowed_.data(), plan_->out.data());
  const std::size_t half = nfft_ / 2;
  // transform_real packs the real DC and Nyquist values into out[0].
  out[0] = std::abs(plan_->out[0].real()) * 0.5 * amplitude_gain_;
  out[half] = std::abs(plan_->out[0].imag()) * 0.5 * amplitude_gain_;
  for (std::size_t k = 1; k < half; ++k) out[k] = std::abs(plan_->out[k]) * amplitude_gain_;
}

const std::complex<double>* SpectrumAnalyzer::complex_spectrum() const {
  return valid() ? plan_->out.data() : nullptr;
}

std::complex<double> SpectrumAnalyzer::window_kernel(double delta_lines) const {
  // Hann w[n] = ½ − ¼e^{i2πn/N} − ¼e^{−i2πn/N}: three shifted geometric sums
  // G(δ) = Σ_{n<N} e^{i2πδn/N} = (1 − e^{i2πδ}) / (1 − e^{i2πδ/N}), N at δ ≡ 0.
  const double n = static_cast<double>(nfft_);
  auto geometric = [n](double d) {
    const double r = d - n * std::round(d / n);  // periodic in N
    if (std::abs(r) < 1e-12) return std::complex<double>(n, 0.0);
    const std::complex<double> num = 1.0 - std::polar(1.0, 2.0 * std::numbers::pi * d);
    const std::complex<double> den = 1.0 - std::polar(1.0, 2.0 * std::numbers::pi * d / n);
    return num / den;
  };
  return 0.5 * geometric(delta_lines) - 0.25 * geometric(delta_lines + 1.0) -
         0.25 * geometric(delta_lines - 1.0);
}

double SpectrumAnalyzer::tone_amplitude(const double* spectrum, double centre_line,
                                        std::size_t half_width) const {
  if (!valid() || !(centre_line >= 0.0)) return 0.0;
  const auto centre = static_cast<long long>(std::llround(centre_line));
  const long long last = static_cast<long long>(lines()) - 1;
  const long long w = static_cast<long long>(std::max<std::size_t>(half_width, 2));
  double energy = 0.0;
  for (long long k = std::max(1LL, centre - w); k <= std::min(last, centre + w); ++k) {
    energy += spectrum[k] * spectrum[k];
  }
  return std::sqrt(energy / kHannEnbwLines);
}

void add_unexplained_energy(const double* measured, std::size_t measured_lines,
                            const double* simulated, std::size_t simulated_lines, std::size_t last,
                            double& miss, double& total) {
  for (std::size_t k = 1; k <= last && k < measured_lines; ++k) {
    const double a_s = k < simulated_lines ? simulated[k] : 0.0;
    const double d = measured[k] - a_s;
    miss += d * d;
    total += measured[k] * measured[k];
  }
}

double rms(const double* x, std::size_t n) {
  if (n == 0) return 0.0;
  double mean = 0.0;
  for (std::size_t i = 0; i < n; ++i) mean += x[i];
  mean /= static_cast<double>(n);
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) sum += (x[i] - mean) * (x[i] - mean);
  return std::sqrt(sum / static_cast<double>(n));
}

DspStatus check_waveform(const double* x, std::size_t n, double flat_threshold) {
  if (n == 0) return DspStatus::kTooShort;
  double lo = x[0];
  double hi = x[0];
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(x[i])) return DspStatus::kNonFinite;
    lo = std::min(lo, x[i]);
    hi = std::max(hi, x[i]);
  }
  if (!(hi - lo > flat_threshold)) return DspStatus::kFlat;
  // Clipping: an ADC or amplifier at its rail repeats the same value at the
  // waveform's extreme; a healthy waveform passes its peak in one sample.
  const double near_hi = hi - 0.02 * (hi - lo);
  const double near_lo = lo + 0.02 * (hi - lo);
  std::size_t clipped = 0;
  std::size_t run = 1;
  for (std::size_t i = 1; i <= n; ++i) {
    if (i < n && x[i] == x[i - 1] && (x[i] >= near_hi || x[i] <= near_lo)) {
      ++run;
      continue;
    }
    if (run >= 3) clipped += run;
    run = 1;
  }
  if (clipped * 1000 > n) return DspStatus::kClipped;
  return DspStatus::kOk;
}

}  // namespace model::dsp
