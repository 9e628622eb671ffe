#include "model/diagnosis/signal.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace model::diagnosis {

WaveformStatistics statistics(const double* x, std::size_t n) {
  WaveformStatistics s;
  if (n == 0) return s;
  double mean = 0.0;
  for (std::size_t i = 0; i < n; ++i) mean += x[i];
  mean /= static_cast<double>(n);
  double m2 = 0.0, m4 = 0.0, peak = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = x[i] - mean;
    const double d2 = d * d;
    m2 += d2;
    m4 += d2 * d2;
    peak = std::max(peak, std::abs(d));
  }
  m2 /= static_cast<double>(n);
  m4 /= static_cast<double>(n);
  s.mean = mean;
  if (!(m2 > 0.0)) return s;
  s.rms = std::sqrt(m2);
  s.peak = peak;
  s.crest_factor = peak / s.rms;
  s.kurtosis = m4 / (m2 * m2);
  return s;
}

void hann_amplitude_spectrum(const double* x, std::size_t n, const Fft& fft,
                             std::vector<double>& out) {
  out.assign(n / 2 + 1, 0.0);
  if (n < 2 || fft.size() != n) return;
  double mean = 0.0;
  for (std::size_t i = 0; i < n; ++i) mean += x[i];
  mean /= static_cast<double>(n);
  std::vector<Complex> in(n), spec(n);
  double sum_w = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    // Periodic Hann window w[i] = 0.5·(1 − cos(2πi/N)) (Harris 1978).
    const double w =
        0.5 *
        (1.0 - std::cos(2.0 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(n)));
    sum_w += w;
    in[i] = Complex((x[i] - mean) * w, 0.0);
  }
  fft.forward(in.data(), spec.data());
  const double gain = 2.0 / sum_w;
  for (std::size_t k = 0; k <= n / 2; ++k) out[k] = std::abs(spec[k]) * gain;
  out[0] *= 0.5;
  if (n % 2 == 0) out[n / 2] *= 0.5;
}

double lobe_amplitude(const std::vector<double>& spectrum, double line, std::size_t half_width) {
  if (spectrum.empty() || !(line >= 0.0)) return 0.0;
  const auto c = static_cast<long long>(std::llround(line));
  const auto w = static_cast<long long>(std::max<std::size_t>(half_width, 1));
  const auto last = static_cast<long long>(spectrum.size()) - 1;
  double e = 0.0;
  for (long long k = std::max(1LL, c - w); k <= std::min(last, c + w); ++k)
    e += spectrum[static_cast<std::size_t>(k)] * spectrum[static_cast<std::size_t>(k)];
  return std::sqrt(e / kHannEnbw);
}

double lobe_noise_floor(const std::vector<double>& spectrum, double line, std::size_t half_width,
                        std::size_t reach) {
  if (spectrum.empty() || !(line >= 0.0)) return 0.0;
  const auto c = static_cast<long long>(std::llround(line));
  const auto w = static_cast<long long>(half_width);
  const auto r = static_cast<long long>(reach);
  const auto last = static_cast<long long>(spectrum.size()) - 1;
  std::vector<double> near;
  near.reserve(static_cast<std::size_t>(2 * r + 1));
  for (long long k = c - r; k <= c + r; ++k) {
    if (k < 1 || k > last || std::abs(k - c) <= w + 1) continue;
    near.push_back(spectrum[static_cast<std::size_t>(k)]);
  }
  if (near.empty()) return 0.0;
  auto mid = near.begin() + static_cast<long>(near.size() / 2);
  std::nth_element(near.begin(), mid, near.end());
  return *mid * std::sqrt(static_cast<double>(2 * half_width + 1) / kHannEnbw);
}

namespace {
// FFT of x zero-padded to a 2·3·5-smooth length ≥ n.
std::vector<Complex> padded_spectrum(const double* x, std::size_t n, const Fft& fft) {
  std::vector<Complex> in(fft.size(), Complex(0.0, 0.0)), out(fft.size());
  for (std::size_t i = 0; i < n; ++i) in[i] = Complex(x[i], 0.0);
  fft.forward(in.data(), out.data());
  return out;
}
}  // namespace

std::vector<Complex> band_analytic(const double* x, std::size_t n, double fs_hz, double f_lo_hz,
                                   double f_hi_hz) {
  std::vector<Complex> out(n, Complex(0.0, 0.0));
  if (n < 2 || !(fs_hz > 0.0)) return out;
  const Fft fft(fft_size_at_least(n));
  const std::size_t m = fft.size();
  std::vector<Complex> spec = padded_spectrum(x, n, fft);
  const double df = fs_hz / static_cast<double>(m);
  // Analytic signal: 2·X_k for positive frequencies in the band, 0 elsewhere (DC once).
  for (std::size_t k = 0; k < m; ++k) {
    const double f = static_cast<double>(k) * df;
    const bool positive = 2 * k < m;
    if (!positive || f < f_lo_hz || f >= f_hi_hz) {
      spec[k] = Complex(0.0, 0.0);
    } else if (k > 0) {
      spec[k] *= 2.0;
    }
  }
  std::vector<Complex> y(m);
  fft.inverse(spec.data(), y.data());
  std::copy(y.begin(), y.begin() + static_cast<long>(n), out.begin());
  return out;
}

std::vector<double> squared_envelope(const double* x, std::size_t n, double fs_hz, double f_lo_hz,
                                     double f_hi_hz) {
  const std::vector<Complex> a = band_analytic(x, n, fs_hz, f_lo_hz, f_hi_hz);
  std::vector<double> e(n);
  for (std::size_t i = 0; i < n; ++i) e[i] = std::norm(a[i]);
  return e;
}

namespace {
std::vector<Complex> tapered_spectrum(const double* x, std::size_t n, const Fft& fft) {
  // Tukey taper over the first and last kCpwTaper of the record: whitened, the step
  // at the record's ends (a line whose period does not divide the record leaks) would
  // otherwise become an impulse at both ends, the most impulsive thing in the signal.
  std::vector<double> tapered(x, x + n);
  const auto edge = static_cast<std::size_t>(kCpwTaper * static_cast<double>(n));
  for (std::size_t i = 0; i < edge; ++i) {
    const double w =
        0.5 *
        (1.0 - std::cos(std::numbers::pi * static_cast<double>(i) / static_cast<double>(edge)));
    tapered[i] *= w;
    tapered[n - 1 - i] *= w;
  }
  return padded_spectrum(tapered.data(), n, fft);
}

std::vector<double> real_part(const std::vector<Complex>& spec, const Fft& fft, std::size_t n) {
  std::vector<Complex> y(fft.size());
  fft.inverse(spec.data(), y.data());
  std::vector<double> out(n, 0.0);
  for (std::size_t i = 0; i < n && i < y.size(); ++i) out[i] = y[i].real();
  return out;
}

std::vector<double> prewhiten(const double* x, std::size_t n, double fs_hz,
                              WhiteningReference* reference) {
  if (n < 2) return std::vector<double>(n, 0.0);
  const Fft fft(fft_size_at_least(n));
  std::vector<Complex> spec = tapered_spectrum(x, n, fft);
  if (reference != nullptr) {
    const std::size_t half = fft.size() / 2;
    reference->bin_hz = fs_hz / static_cast<double>(fft.size());
    reference->cumulative.assign(half + 2, 0.0);
    const double scale = reference->bin_hz / (fs_hz * static_cast<double>(n));
    for (std::size_t k = 0; k <= half; ++k)
      reference->cumulative[k + 1] = reference->cumulative[k] + std::norm(spec[k]) * scale;
  }
  double top = 0.0;
  for (const Complex& c : spec) top = std::max(top, std::abs(c));
  const double floor = 1e-12 * top;
  for (Complex& c : spec) {
    const double a = std::abs(c);
    c = a > floor ? c / a : Complex(0.0, 0.0);
  }
  spec[0] = Complex(0.0, 0.0);  // the mean carries no diagnostic information
  return real_part(spec, fft, n);
}
}  // namespace

std::vector<double> cepstral_prewhiten(const double* x, std::size_t n) {
  return prewhiten(x, n, 1.0, nullptr);
}

std::vector<double> cepstral_prewhiten(const double* x, std::size_t n, double fs_hz,
                                       WhiteningReference& reference) {
  return prewhiten(x, n, fs_hz, &reference);
}

double WhiteningReference::mean_psd(double f_lo_hz, double f_hi_hz) const {
  if (!valid()) return 0.0;
  const auto bins = static_cast<double>(cumulative.size() - 1);
  // Running sum at frequency f: bins wholly below plus the covered part of the current one.
  auto at = [&](double f) {
    const double u = std::clamp(f / bin_hz + 0.5, 0.0, bins);
    const auto j = static_cast<std::size_t>(std::floor(u));
    if (j + 1 >= cumulative.size()) return cumulative.back();
    return cumulative[j] + (u - static_cast<double>(j)) * (cumulative[j + 1] - cumulative[j]);
  };
  const double width = f_hi_hz - f_lo_hz;
  if (!(width > 0.0)) return 0.0;
  if (width < bin_hz) {  // narrower than a bin: that bin's value
    const double c = 0.5 * (f_lo_hz + f_hi_hz);
    return (at(c + 0.5 * bin_hz) - at(c - 0.5 * bin_hz)) / bin_hz;
  }
  return (at(f_hi_hz) - at(f_lo_hz)) / width;
}

std::vector<double> whiten_like(const double* x, std::size_t n, double fs_hz,
                                const WhiteningReference& reference) {
  if (n < 2 || !reference.valid() || !(fs_hz > 0.0)) return std::vector<double>(n, 0.0);
  const Fft fft(fft_size_at_least(n));
  const std::size_t m = fft.size();
  std::vector<Complex> spec = tapered_spectrum(x, n, fft);
  const double df = fs_hz / static_cast<double>(m);
  const double to_bin = fs_hz * static_cast<double>(n);
  spec[0] = Complex(0.0, 0.0);
  for (std::size_t k = 1; k < m; ++k) {
    const std::size_t kk = 2 * k <= m ? k : m - k;  // its positive frequency
    const double f = static_cast<double>(kk) * df;
    const double p = reference.mean_psd(f - 0.5 * df, f + 0.5 * df);
    spec[k] = p > 0.0 ? spec[k] / std::sqrt(p * to_bin) : Complex(0.0, 0.0);
  }
  return real_part(spec, fft, n);
}

std::vector<double> real_cepstrum(const double* x, std::size_t n) {
  std::vector<double> out(n, 0.0);
  if (n < 2) return out;
  const Fft fft(n);
  std::vector<Complex> in(n), spec(n);
  for (std::size_t i = 0; i < n; ++i) in[i] = Complex(x[i], 0.0);
  fft.forward(in.data(), spec.data());
  double top = 0.0;
  for (const Complex& c : spec) top = std::max(top, std::abs(c));
  const double floor = std::max(1e-12 * top, 1e-300);
  for (std::size_t k = 0; k < n; ++k)
    in[k] = Complex(std::log(std::max(std::abs(spec[k]), floor)), 0.0);
  fft.inverse(in.data(), spec.data());
  for (std::size_t q = 0; q < n; ++q) out[q] = spec[q].real();
  return out;
}

Kurtogram kurtogram(const double* x, std::size_t n, double fs_hz, const KurtogramConfig& config) {
  Kurtogram result;
  result.best.kurtosis = -1e300;
  if (n < 16 || !(fs_hz > 0.0)) return result;
  const Fft fft(fft_size_at_least(n));
  const std::size_t m = fft.size();
  const std::vector<Complex> spec = padded_spectrum(x, n, fft);
  const double half_lines = static_cast<double>(m) / 2.0;  // lines from 0 to fs/2
  // Number of decimated samples that come from the signal (the rest is zero padding).
  auto evaluate = [&](double level, double lo_frac, double hi_frac) {
    KurtogramBand band;
    band.level = level;
    band.f_lo_hz = lo_frac * fs_hz / 2.0;
    band.f_hi_hz = hi_frac * fs_hz / 2.0;
    if (band.f_hi_hz - band.f_lo_hz < config.min_bandwidth_hz) return;
    const auto k0 = static_cast<std::size_t>(std::ceil(lo_frac * half_lines));
    const auto k1 = std::min(static_cast<std::size_t>(std::ceil(hi_frac * half_lines)), m / 2);
    if (k1 <= k0 + 1) return;
    const std::size_t lines = k1 - k0;
    const Fft band_fft(fft_size_at_least(lines));
    std::vector<Complex> in(band_fft.size(), Complex(0.0, 0.0)), c(band_fft.size());
    for (std::size_t k = 0; k < lines; ++k) in[k] = spec[k0 + k];
    band_fft.inverse(in.data(), c.data());
    // Keep the decimated samples that cover the signal, not its zero padding.
    const auto used = std::max<std::size_t>(
        4, static_cast<std::size_t>(static_cast<double>(band_fft.size()) * static_cast<double>(n) /
                                    static_cast<double>(m)));
    double m2 = 0.0, m4 = 0.0;
    for (std::size_t i = 0; i < std::min(used, c.size()); ++i) {
      const double p = std::norm(c[i]);
      m2 += p;
      m4 += p * p;
    }
    const double count = static_cast<double>(std::min(used, c.size()));
    m2 /= count;
    m4 /= count;
    band.kurtosis = m2 > 0.0 ? m4 / (m2 * m2) - 2.0 : 0.0;
    result.bands.push_back(band);
    if (band.f_lo_hz >= config.min_frequency_hz && band.kurtosis > result.best.kurtosis)
      result.best = band;
  };
  for (int l = 0; l <= config.max_level; ++l) {
    const double bands = std::exp2(static_cast<double>(l));
    for (int b = 0; b < static_cast<int>(bands); ++b)
      evaluate(static_cast<double>(l), b / bands, (b + 1) / bands);
    if (l >= 1) {
      const double thirds = 3.0 * std::exp2(static_cast<double>(l - 1));
      const double level = static_cast<double>(l) + std::log2(1.5);  // (fs/2)/bandwidth = 3·2^(l−1)
      for (int b = 0; b < static_cast<int>(thirds); ++b)
        evaluate(level, b / thirds, (b + 1) / thirds);
    }
  }
  return result;
}

std::vector<double> lowpass(const double* x, std::size_t n, double fs_hz, double cutoff_hz) {
  std::vector<double> out(x, x + n);
  if (n < 2 || !(fs_hz > 0.0) || cutoff_hz >= fs_hz / 2.0) return out;
  const Fft fft(fft_size_at_least(n));
  const std::size_t m = fft.size();
  std::vector<Complex> spec = padded_spectrum(x, n, fft);
  const double df = fs_hz / static_cast<double>(m);
  for (std::size_t k = 1; k < m; ++k) {
    const std::size_t kk = std::min(k, m - k);
    if (static_cast<double>(kk) * df > cutoff_hz) spec[k] = Complex(0.0, 0.0);
  }
  std::vector<Complex> y(m);
  fft.inverse(spec.data(), y.data());
  for (std::size_t i = 0; i < n; ++i) out[i] = y[i].real();
  return out;
}

}  // namespace model::diagnosis
