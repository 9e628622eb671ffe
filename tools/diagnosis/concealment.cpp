#include "concealment.hpp"

#include <algorithm>
#include <cmath>
#include <functional>

#include "model/diagnosis/fft.hpp"
#include "model/diagnosis/signal.hpp"

namespace tools::diagnosis {

namespace md = model::diagnosis;

namespace {
std::vector<double> spectrum(const std::vector<double>& x) {
  const std::size_t n = md::fft_size_at_most(x.size());
  const md::Fft fft(n);
  std::vector<double> a;
  md::hann_amplitude_spectrum(x.data(), n, fft, a);
  return a;
}
}  // namespace

Concealment concealment(const std::vector<std::vector<double>>& with,
                        const std::vector<std::vector<double>>& without,
                        const std::vector<std::vector<double>>& recorded) {
  Concealment c;
  c.line_margin_db = 1e300;
  for (std::size_t ch = 0; ch < with.size(); ++ch) {
    const md::WaveformStatistics sw = md::statistics(with[ch].data(), with[ch].size());
    const md::WaveformStatistics s0 = md::statistics(without[ch].data(), without[ch].size());
    c.rms_change = std::max(c.rms_change, std::abs(sw.rms / s0.rms - 1.0));
    std::vector<double> diff(with[ch].size());
    for (std::size_t i = 0; i < diff.size(); ++i) diff[i] = with[ch][i] - without[ch][i];
    const std::vector<double> d = spectrum(diff);
    const std::vector<double> r = spectrum(recorded[ch]);
    const double strongest = *std::max_element(d.begin() + 1, d.end());
    std::vector<double> peaks;
    for (std::size_t k = 2; k + 2 < r.size(); ++k)
      if (r[k] > r[k - 1] && r[k] >= r[k + 1]) peaks.push_back(r[k]);
    std::sort(peaks.begin(), peaks.end(), std::greater<>());
    const double tenth = peaks.size() >= 10 ? peaks[9] : (peaks.empty() ? 0.0 : peaks.back());
    if (strongest > 0.0 && tenth > 0.0)
      c.line_margin_db = std::min(c.line_margin_db, 20.0 * std::log10(tenth / strongest));
  }
  return c;
}

}  // namespace tools::diagnosis
