#pragma once
// Recording bundle I/O, format `drivetwin-recording/1`
// (shared/reference/recording-bundle.md): a directory holding recording.json,
// the CMS samples (cms.wav: IEEE float 32-bit interleaved, or cms.csv) and an
// optional scada.csv.
//
// Thread context: start-up / tools / non-real-time threads only. Reading and
// writing allocate and do file I/O; nothing here is meant for the RT loop (the
// replay backends load a bundle at configure() and play it from memory).
// No exceptions escape: every failure is returned as a BundleError that names
// the file, the field and what was expected.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace hal {

inline constexpr const char* kRecordingFormat = "drivetwin-recording/1";

/// One CMS channel as described in recording.json.
struct BundleChannel {
  std::string name;       // unique within the bundle; CSV column name
  std::string location;   // component id of the drivetrain (b1..b6, hss, ...)
  std::string direction;  // "radial", "axial", ... ("" when absent)
  std::string kind;       // "once_per_rev" for a tacho, "" otherwise
  std::string unit;       // e.g. "m/s^2", "V"
};

/// Mean operating point over the recording.
struct BundleOperatingPoint {
  double rotor_speed_rpm = 0.0;           // [rpm] required
  std::optional<double> wind_speed_mps;   // [m/s]
  std::optional<double> input_torque_nm;  // [N·m] rotor (gearbox input) torque
};

/// One row of scada.csv. Columns other than t_s and wind_speed_mps may be absent.
struct BundleScadaRow {
  double t_s = 0.0;                       // [s] since the start of the recording
  double wind_speed_mps = 0.0;            // [m/s]
  std::optional<double> rotor_speed_rpm;  // [rpm]
  std::optional<double> power_kw;         // [kW]
  std::optional<double> pitch_deg;        // [deg]
  std::optional<double> torque_nm;        // [N·m]
};

/// A whole bundle in memory.
struct Recording {
  std::string drivetrain = "paper-2mw";  // drivetrain name, or a path relative to the bundle
  double sample_rate_hz = 0.0;           // [Hz]
  std::string samples_file = "cms.wav";  // "*.wav" or "*.csv"
  std::vector<BundleChannel> channels;
  BundleOperatingPoint operating_point;
  std::string start_utc;  // ISO 8601, "" when absent
  std::string notes;
  /// samples[c][i]: channel c (order of `channels`), sample i, in the channel's unit.
  std::vector<std::vector<double>> samples;
  std::vector<BundleScadaRow> scada;  // empty: no scada.csv

  std::size_t sample_count() const { return samples.empty() ? 0 : samples.front().size(); }
  /// Index of the channel named `name`, if any.
  std::optional<std::size_t> channel_index(const std::string& name) const;
};

/// The turbine's range, against which a bundle's operating point is checked.
/// The bundle format is turbine-agnostic, so the caller (app/, tools/) fills
/// these from its drivetrain description. A value <= 0 disables that upper bound;
/// the lower bounds (non-negative, finite) always apply.
struct OperatingRange {
  double max_rotor_speed_rpm = 0.0;  // [rpm]
  double max_wind_speed_mps = 0.0;   // [m/s]
  double max_input_torque_nm = 0.0;  // [N·m]
};

/// What was wrong with a bundle: printable as "<file>: <field>: <message>".
struct BundleError {
  std::string file;     // path of the offending file ("recording.json", ".../cms.wav")
  std::string field;    // JSON key, CSV row/column, WAV chunk; "" when the whole file
  std::string message;  // what was found and what was expected
  std::string to_string() const;
};

/// Result of read_bundle: a recording or an error, never both.
struct BundleReadResult {
  std::optional<Recording> recording;
  BundleError error;  // meaningful only when !recording
  /// What read_bundle changed on the way in, one printable line each (unit conversions,
  /// e.g. "channels[0] 'point1': converted from g to m/s^2 (x 9.80665)").
  std::vector<std::string> notes;
  explicit operator bool() const { return recording.has_value(); }
};

// ---- Units -----------------------------------------------------------------
// A channel's `unit` must be one the project knows; read_bundle converts the
// samples to the SI unit of its quantity (a CMS exporting in g is common) and
// refuses any other unit by name, so that a value is never taken in the wrong unit.

enum class UnitQuantity : std::uint8_t { kAcceleration, kVelocity, kDisplacement, kVoltage };

struct UnitInfo {
  UnitQuantity quantity = UnitQuantity::kAcceleration;
  double to_si = 1.0;             // SI value = file value × to_si
  const char* si_unit = "m/s^2";  // the unit written after conversion
};

/// The known units: acceleration m/s^2 (also m/s², m/s2), g (standard gravity
/// 9.80665 m/s², ISO 80000-3), mm/s^2; velocity m/s, mm/s; displacement m, mm, um
/// (also µm); voltage V, mV. Case-sensitive (mV is not MV). nullopt otherwise.
std::optional<UnitInfo> parse_unit(const std::string& unit);

/// The list of known units, for messages ("m/s^2, g, ...").
const char* known_units();

/// Reads and validates the bundle directory `dir` (every rule of "Bad bundles"), and
/// converts every channel to the SI unit of its quantity (parse_unit; listed in notes).
/// @param dir    bundle directory (holding recording.json)
/// @param range  the turbine's operating range for the operating-point check
[[nodiscard]] BundleReadResult read_bundle(const std::filesystem::path& dir,
                                           const OperatingRange& range = {});

/// Validates `rec` as read_bundle would (without touching the disk).
/// @return the first problem found, or nullopt. `file` names the file the
///         field would be written to.
[[nodiscard]] std::optional<BundleError> validate_recording(const Recording& rec,
                                                            const OperatingRange& range = {});

/// Writes `rec` as a bundle into `dir` (created if missing). The recording is
/// validated first; on any error nothing is left behind: files are written
/// under temporary names and renamed into place only when all were written.
/// @return nullopt on success, else the error.
[[nodiscard]] std::optional<BundleError> write_bundle(const std::filesystem::path& dir,
                                                      const Recording& rec,
                                                      const OperatingRange& range = {});

// ---- Lower-level pieces, exposed for tests, fuzzers and tools -------------

/// Samples of a WAV file: IEEE float 32-bit (format 3, or EXTENSIBLE with the
/// float sub-format), interleaved.
struct WavData {
  std::uint32_t sample_rate_hz = 0;
  std::uint16_t channels = 0;
  std::vector<float> interleaved;  // frames × channels
};

/// Parses WAV bytes held in memory. `file` is used for messages only.
[[nodiscard]] std::optional<BundleError> parse_wav(const std::string& bytes,
                                                   const std::string& file, WavData& out);

/// Parses a CMS samples CSV (header `t_s,<names...>`) for the given channels,
/// matching columns by name, and checks t_s against the sample rate.
[[nodiscard]] std::optional<BundleError> parse_samples_csv(
    const std::string& text, const std::string& file, const std::vector<BundleChannel>& channels,
    double sample_rate_hz, std::vector<std::vector<double>>& out);

/// Parses scada.csv text (header `t_s,wind_speed_mps,...`).
[[nodiscard]] std::optional<BundleError> parse_scada_csv(const std::string& text,
                                                         const std::string& file,
                                                         std::vector<BundleScadaRow>& out);

/// Parses recording.json text into `rec` (metadata only; samples untouched).
[[nodiscard]] std::optional<BundleError> parse_recording_json(const std::string& text,
                                                              const std::string& file,
                                                              Recording& rec);

}  // namespace hal
