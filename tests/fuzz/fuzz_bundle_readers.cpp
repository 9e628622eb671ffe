// Fuzz the recording bundle's readers and the SCADA CSV reader on bytes in
// memory: recording.json, the WAV parser, the CMS samples CSV, scada.csv, and
// hal/scada_csv.hpp's streaming reader with the Kelmarsh mapping. The first
// byte picks the reader. Property: no crash/UB, and every rejection carries a
// message naming the file.
#include <cstdint>
#include <cstdlib>
#include <string>

#include "hal/recording_bundle.hpp"
#include "hal/scada_csv.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  const std::string file = "fuzz-input";
  auto named = [&](const std::optional<hal::BundleError>& e) {
    if (e && (e->file != file || e->message.empty())) std::abort();
  };
  switch (data[0] % 5) {
    case 0: {
      hal::Recording rec;
      named(hal::parse_recording_json(text, file, rec));
      break;
    }
    case 1: {
      hal::WavData wav;
      const auto e = hal::parse_wav(text, file, wav);
      named(e);
      if (!e && wav.channels != 0 && wav.interleaved.size() % wav.channels != 0) std::abort();
      break;
    }
    case 2: {
      const std::vector<hal::BundleChannel> channels{{"point1", "b5", "radial", "", "m/s^2"},
                                                     {"tacho", "hss", "", "once_per_rev", "V"}};
      std::vector<std::vector<double>> out;
      const auto e = hal::parse_samples_csv(text, file, channels, 4.0, out);
      named(e);
      if (!e && (out.size() != 2 || out[0].size() != out[1].size())) std::abort();
      break;
    }
    case 3: {
      std::vector<hal::BundleScadaRow> rows;
      named(hal::parse_scada_csv(text, file, rows));
      break;
    }
    case 4: {
      hal::ScadaCsvReader reader;
      if (!reader.open_text(text, file, hal::kelmarsh_scada_columns())) break;
      hal::ScadaRow row;
      for (int i = 0; i < 10000 && reader.next(row) == hal::ScadaReadResult::kRow; ++i) {
      }
      break;
    }
  }
  return 0;
}
