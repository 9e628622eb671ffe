#pragma once
// The test of concealment, for any generator: an effect is concealed when it
// changes the RMS of each channel by less than 10 % and its strongest spectral line is at
// least 6 dB below the tenth-highest peak of the raw spectrum.
//   rms_change  = |RMS(with) / RMS(without) − 1|, noise-free waveforms;
//   line_margin = 20·log10(tenth-highest peak of the raw recording's spectrum /
//                 strongest line of (with − without)) [dB], Hann spectra of the whole record.
// Host tool: allocates.

#include <vector>

namespace tools::diagnosis {

struct Concealment {
  double rms_change = 0.0;      // [-] largest over the channels
  double line_margin_db = 0.0;  // [dB] smallest over the channels
  bool concealed() const { return rms_change < 0.10 && line_margin_db >= 6.0; }
};

/// with[c], without[c]: noise-free channel c; recorded[c]: what the bundle holds.
Concealment concealment(const std::vector<std::vector<double>>& with,
                        const std::vector<std::vector<double>>& without,
                        const std::vector<std::vector<double>>& recorded);

}  // namespace tools::diagnosis
