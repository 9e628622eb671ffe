// Recording bundle reader/writer against shared/reference/recording-bundle.md:
// hand-built files (bytes written out here from the WAV and JSON specs), round
// trips, and every "Bad bundles" rule (message names file, field, expectation;
// nothing written on error).
#include <gtest/gtest.h>

#include "hal/recording_bundle.hpp"

#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

namespace {

namespace fs = std::filesystem;

class TempDir {
 public:
  TempDir() {
    static int counter = 0;
    path_ = fs::temp_directory_path() /
            ("drivetwin-bundle-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

void write(const fs::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary);
  out << bytes;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

const char* const kJson = R"({
  "format": "drivetwin-recording/1",
  "drivetrain": "paper-2mw",
  "sample_rate_hz": 4,
  "samples": "cms.wav",
  "channels": [
    {"name": "point1", "location": "b5", "direction": "radial", "unit": "m/s^2"},
    {"name": "tacho",  "location": "hss", "kind": "once_per_rev", "unit": "V"}
  ],
  "operating_point": {"rotor_speed_rpm": 8.33, "wind_speed_mps": 6.75, "input_torque_nm": 361747},
  "start_utc": "2026-03-14T02:10:00Z",
  "notes": "free text"
})";

void le32(std::string& s, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}
void le16(std::string& s, std::uint16_t v) {
  s.push_back(static_cast<char>(v & 0xFF));
  s.push_back(static_cast<char>(v >> 8));
}

// A canonical 44-byte-header WAV: format 3 (IEEE float), 32 bits, interleaved.
std::string float_wav(std::uint16_t channels, std::uint32_t rate,
                      const std::vector<std::uint32_t>& words) {
  std::string s = "RIFF";
  le32(s, static_cast<std::uint32_t>(36 + 4 * words.size()));
  s += "WAVEfmt ";
  le32(s, 16);
  le16(s, 3);
  le16(s, channels);
  le32(s, rate);
  le32(s, rate * channels * 4);
  le16(s, static_cast<std::uint16_t>(channels * 4));
  le16(s, 32);
  s += "data";
  le32(s, static_cast<std::uint32_t>(4 * words.size()));
  for (auto w : words) le32(s, w);
  return s;
}

// IEEE 754 single bit patterns written out by hand.
constexpr std::uint32_t kOne = 0x3F800000;       // 1.0f
constexpr std::uint32_t kMinusTwo = 0xC0000000;  // -2.0f
constexpr std::uint32_t kHalf = 0x3F000000;      // 0.5f
constexpr std::uint32_t kZero = 0x00000000;      // 0.0f
constexpr std::uint32_t kNan = 0x7FC00000;       // quiet NaN

hal::Recording sample_recording(const std::string& samples_file) {
  hal::Recording r;
  r.sample_rate_hz = 25600;
  r.samples_file = samples_file;
  r.channels = {{"point1", "b5", "radial", "", "m/s^2"}, {"point2", "b3", "radial", "", "m/s^2"}};
  r.operating_point.rotor_speed_rpm = 8.33;
  r.operating_point.input_torque_nm = 361747.0;
  r.start_utc = "2026-03-14T02:10:00Z";
  r.samples.assign(2, std::vector<double>(300));
  for (std::size_t i = 0; i < 300; ++i) {
    // float-representable values so the WAV round trip is exact
    r.samples[0][i] =
        static_cast<double>(static_cast<float>(std::sin(0.01 * static_cast<double>(i))));
    r.samples[1][i] = static_cast<double>(i) * 0.25 - 10.0;
  }
  r.scada = {{0.0, 6.5, 8.3, 520.0, std::nullopt, 360000.0},
             {1.0, 6.75, 8.33, 530.0, std::nullopt, 361747.0}};
  return r;
}

TEST(RecordingBundle, ReadsAHandWrittenWavBundleWithChannelsInJsonOrder) {
  // Arrange: 2 channels x 2 frames: frame0 = (1.0, -2.0), frame1 = (0.5, 0.0)
  TempDir dir;
  write(dir.path() / "recording.json", kJson);
  write(dir.path() / "cms.wav", float_wav(2, 4, {kOne, kMinusTwo, kHalf, kZero}));

  // Act
  const auto result = hal::read_bundle(dir.path());

  // Assert
  ASSERT_TRUE(result) << result.error.to_string();
  const hal::Recording& r = *result.recording;
  EXPECT_EQ(r.drivetrain, "paper-2mw");
  EXPECT_DOUBLE_EQ(r.sample_rate_hz, 4.0);
  ASSERT_EQ(r.channels.size(), 2u);
  EXPECT_EQ(r.channels[1].kind, "once_per_rev");
  EXPECT_EQ(r.channels[0].direction, "radial");
  ASSERT_EQ(r.sample_count(), 2u);
  EXPECT_EQ(r.samples[0][0], 1.0);
  EXPECT_EQ(r.samples[1][0], -2.0);
  EXPECT_EQ(r.samples[0][1], 0.5);
  EXPECT_EQ(r.samples[1][1], 0.0);
  EXPECT_DOUBLE_EQ(r.operating_point.rotor_speed_rpm, 8.33);
  EXPECT_DOUBLE_EQ(*r.operating_point.input_torque_nm, 361747.0);
  EXPECT_EQ(r.start_utc, "2026-03-14T02:10:00Z");
  EXPECT_TRUE(r.scada.empty());
}

TEST(RecordingBundle, SkipsUnknownChunksAndOddPaddingInAWav) {
  // Arrange: a LIST chunk of odd length (3 bytes + 1 pad byte) before data.
  TempDir dir;
  std::string wav = float_wav(2, 4, {kOne, kMinusTwo});
  std::string list = "LIST";
  le32(list, 3);
  list += "abc";
  list.push_back('\0');
  wav.insert(36, list);
  write(dir.path() / "recording.json", kJson);
  write(dir.path() / "cms.wav", wav);

  // Act
  const auto result = hal::read_bundle(dir.path());

  // Assert
  ASSERT_TRUE(result) << result.error.to_string();
  EXPECT_EQ(result.recording->samples[1][0], -2.0);
}

TEST(RecordingBundle, ReadsCsvSamplesMatchingColumnsByNameNotPosition) {
  // Arrange: columns in the opposite order of recording.json's channels.
  TempDir dir;
  std::string json = kJson;
  json.replace(json.find("cms.wav"), 7, "cms.csv");
  write(dir.path() / "recording.json", json);
  write(dir.path() / "cms.csv", "t_s,tacho,point1\n0,5,0.1\n0.25,0,0.2\n0.5,0,-0.3\r\n");
  write(dir.path() / "scada.csv", "t_s,wind_speed_mps,power_kw\n0,6.5,500\n1,6.9,510\n");

  // Act
  const auto result = hal::read_bundle(dir.path());

  // Assert
  ASSERT_TRUE(result) << result.error.to_string();
  const hal::Recording& r = *result.recording;
  ASSERT_EQ(r.sample_count(), 3u);
  EXPECT_DOUBLE_EQ(r.samples[0][2], -0.3);  // point1
  EXPECT_DOUBLE_EQ(r.samples[1][0], 5.0);   // tacho
  ASSERT_EQ(r.scada.size(), 2u);
  EXPECT_DOUBLE_EQ(r.scada[1].wind_speed_mps, 6.9);
  EXPECT_DOUBLE_EQ(*r.scada[1].power_kw, 510.0);
  EXPECT_FALSE(r.scada[1].rotor_speed_rpm.has_value());
}

TEST(RecordingBundle, WavRoundTripReproducesEverySampleBitForBit) {
  // Arrange
  TempDir dir;
  const hal::Recording original = sample_recording("cms.wav");

  // Act
  const auto werr = hal::write_bundle(dir.path() / "case", original);
  const auto result = hal::read_bundle(dir.path() / "case");

  // Assert
  ASSERT_FALSE(werr) << werr->to_string();
  ASSERT_TRUE(result) << result.error.to_string();
  EXPECT_EQ(result.recording->samples, original.samples);
  EXPECT_EQ(result.recording->channels.size(), 2u);
  EXPECT_EQ(result.recording->channels[1].location, "b3");
  ASSERT_EQ(result.recording->scada.size(), 2u);
  EXPECT_DOUBLE_EQ(*result.recording->scada[1].torque_nm, 361747.0);
  EXPECT_FALSE(result.recording->scada[1].pitch_deg.has_value());
  EXPECT_FALSE(fs::exists(dir.path() / "case" / "cms.wav.tmp-writing"));
}

TEST(RecordingBundle, CsvRoundTripKeepsDoublePrecision) {
  // Arrange: values that float32 could not hold
  TempDir dir;
  hal::Recording original = sample_recording("cms.csv");
  original.samples[0][7] = 0.1234567890123456;

  // Act
  const auto werr = hal::write_bundle(dir.path(), original);
  const auto result = hal::read_bundle(dir.path());

  // Assert
  ASSERT_FALSE(werr) << werr->to_string();
  ASSERT_TRUE(result) << result.error.to_string();
  EXPECT_EQ(result.recording->samples, original.samples);
}

// ---- Bad bundles -----------------------------------------------------------

struct BadCase {
  const char* name;
  std::string json;
  std::string wav;
  const char* file_part;   // expected in BundleError::file
  const char* field_part;  // expected in BundleError::field
  const char* message_part;
};

std::string json_with(const std::string& from, const std::string& to) {
  std::string j = kJson;
  const auto pos = j.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  j.replace(pos, from.size(), to);
  return j;
}

const std::string kGoodWav = float_wav(2, 4, {kOne, kMinusTwo, kHalf, kZero});

class BadBundle : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadBundle, IsRejectedWithAMessageNamingFileFieldAndExpectation) {
  // Arrange
  const BadCase& c = GetParam();
  TempDir dir;
  if (!c.json.empty()) write(dir.path() / "recording.json", c.json);
  if (!c.wav.empty()) write(dir.path() / "cms.wav", c.wav);
  hal::OperatingRange range;
  range.max_rotor_speed_rpm = 1.2 * 14.8;  // reference turbine: rated 14.8 rpm + 20 %
  range.max_wind_speed_mps = 30.0;
  range.max_input_torque_nm = 2.0 * 1.23e6;

  // Act
  const auto result = hal::read_bundle(dir.path(), range);

  // Assert
  ASSERT_FALSE(result) << c.name;
  EXPECT_NE(result.error.file.find(c.file_part), std::string::npos) << result.error.to_string();
  EXPECT_NE(result.error.field.find(c.field_part), std::string::npos) << result.error.to_string();
  EXPECT_NE(result.error.message.find(c.message_part), std::string::npos)
      << result.error.to_string();
}

INSTANTIATE_TEST_SUITE_P(
    EveryRule, BadBundle,
    ::testing::Values(
        BadCase{"missing_json", "", kGoodWav, "recording.json", "", "missing"},
        BadCase{"malformed_json", "{\"format\": ", kGoodWav, "recording.json", "",
                "not valid JSON"},
        BadCase{"unknown_version", json_with("recording/1", "recording/2"), kGoodWav,
                "recording.json", "format", "expected 'drivetwin-recording/1'"},
        BadCase{"zero_rate", json_with("\"sample_rate_hz\": 4", "\"sample_rate_hz\": 0"), kGoodWav,
                "recording.json", "sample_rate_hz", "> 0"},
        BadCase{"negative_rate", json_with("\"sample_rate_hz\": 4", "\"sample_rate_hz\": -4"),
                kGoodWav, "recording.json", "sample_rate_hz", "> 0"},
        BadCase{"rate_is_text", json_with("\"sample_rate_hz\": 4", "\"sample_rate_hz\": \"4\""),
                kGoodWav, "recording.json", "sample_rate_hz", "expected a number"},
        BadCase{"channel_without_unit", json_with(", \"unit\": \"V\"", ""), kGoodWav,
                "recording.json", "channels[1].unit", "missing"},
        BadCase{"duplicate_channel", json_with("\"tacho\"", "\"point1\""), kGoodWav,
                "recording.json", "channels[1].name", "unique"},
        BadCase{"missing_rotor_speed", json_with("\"rotor_speed_rpm\": 8.33, ", ""), kGoodWav,
                "recording.json", "operating_point.rotor_speed_rpm", "missing"},
        BadCase{
            "neither_torque_nor_wind",
            json_with("\"wind_speed_mps\": 6.75, \"input_torque_nm\": 361747", "\"power_kw\": 1"),
            kGoodWav, "recording.json", "operating_point", "at least one"},
        BadCase{"rotor_speed_out_of_range", json_with("8.33", "40"), kGoodWav, "recording.json",
                "operating_point.rotor_speed_rpm", "turbine's range"},
        BadCase{"torque_out_of_range", json_with("361747", "9e6"), kGoodWav, "recording.json",
                "operating_point.input_torque_nm", "turbine's range"},
        BadCase{"negative_wind", json_with("6.75", "-1"), kGoodWav, "recording.json",
                "operating_point.wind_speed_mps", ">= 0"},
        BadCase{"samples_escape_bundle", json_with("\"cms.wav\"", "\"../cms.wav\""), kGoodWav,
                "recording.json", "samples", "inside the bundle"},
        BadCase{"missing_wav", kJson, "", "cms.wav", "", "missing"},
        BadCase{"wav_channel_count", kJson, float_wav(3, 4, {kOne, kOne, kOne}), "cms.wav",
                "fmt chunk", "expected 2"},
        BadCase{"wav_rate_mismatch", kJson, float_wav(2, 8, {kOne, kOne}), "cms.wav", "fmt chunk",
                "expected 4 Hz"},
        BadCase{"wav_not_riff", kJson, "hello, world", "cms.wav", "RIFF", "not a RIFF"},
        BadCase{"wav_truncated", kJson, float_wav(2, 4, {kOne, kOne}).substr(0, 50), "cms.wav",
                "data chunk", "truncated"},
        BadCase{"unknown_unit", json_with("\"unit\": \"m/s^2\"", "\"unit\": \"furlong\""), kGoodWav,
                "recording.json", "channels[0].unit", "'furlong' is not a unit"},
        BadCase{"unknown_kind", json_with("\"once_per_rev\"", "\"twice_per_rev\""), kGoodWav,
                "recording.json", "channels[1].kind", "expected \"once_per_rev\""},
        BadCase{"tacho_not_a_voltage", json_with("\"unit\": \"V\"", "\"unit\": \"g\""), kGoodWav,
                "recording.json", "channels[1].unit", "expected a voltage"},
        BadCase{"wav_non_finite", kJson, float_wav(2, 4, {kOne, kOne, kNan, kOne}), "cms.wav",
                "point1' frame 1", "non-finite"}),
    [](const ::testing::TestParamInfo<BadCase>& p) { return std::string(p.param.name); });

TEST(RecordingBundle, ConvertsAChannelInGToMetresPerSecondSquaredAndSaysSo) {
  // Arrange: point1 in g, the tacho in mV; frames (1.0, -2.0), (0.5, 0.0).
  TempDir dir;
  std::string json = json_with("\"unit\": \"m/s^2\"", "\"unit\": \"g\"");
  json.replace(json.find("\"unit\": \"V\""), 11, "\"unit\": \"mV\"");
  write(dir.path() / "recording.json", json);
  write(dir.path() / "cms.wav", float_wav(2, 4, {kOne, kMinusTwo, kHalf, kZero}));
  // Act
  const auto result = hal::read_bundle(dir.path());
  // Assert: standard gravity 9.80665 m/s² (ISO 80000-3) per g; 1 mV = 1e-3 V.
  ASSERT_TRUE(result) << result.error.to_string();
  const hal::Recording& r = *result.recording;
  EXPECT_EQ(r.channels[0].unit, "m/s^2");
  EXPECT_DOUBLE_EQ(r.samples[0][0], 9.80665);
  EXPECT_DOUBLE_EQ(r.samples[0][1], 0.5 * 9.80665);
  EXPECT_EQ(r.channels[1].unit, "V");
  EXPECT_DOUBLE_EQ(r.samples[1][0], -2e-3);
  ASSERT_EQ(result.notes.size(), 2u);
  EXPECT_NE(result.notes[0].find("'point1': converted from g to m/s^2"), std::string::npos)
      << result.notes[0];
}

TEST(RecordingBundle, RejectsAWavOfIntegerPcm) {
  // Arrange: format 1 (PCM) 16-bit
  TempDir dir;
  std::string wav = float_wav(2, 4, {kOne, kOne});
  wav[20] = 1;   // wFormatTag = 1
  wav[34] = 16;  // wBitsPerSample = 16
  write(dir.path() / "recording.json", kJson);
  write(dir.path() / "cms.wav", wav);

  // Act
  const auto result = hal::read_bundle(dir.path());

  // Assert
  ASSERT_FALSE(result);
  EXPECT_NE(result.error.message.find("expected IEEE float (3) with 32 bits"), std::string::npos)
      << result.error.to_string();
}

TEST(RecordingBundle, RejectsACsvMissingAChannelColumnNamingTheColumn) {
  // Arrange
  TempDir dir;
  write(dir.path() / "recording.json", json_with("cms.wav", "cms.csv"));
  write(dir.path() / "cms.csv", "t_s,point1\n0,1\n");

  // Act
  const auto result = hal::read_bundle(dir.path());

  // Assert
  ASSERT_FALSE(result);
  EXPECT_NE(result.error.file.find("cms.csv"), std::string::npos);
  EXPECT_NE(result.error.message.find("no column 'tacho'"), std::string::npos)
      << result.error.to_string();
}

TEST(RecordingBundle, RejectsANonFiniteCsvSampleNamingLineAndColumn) {
  // Arrange
  TempDir dir;
  write(dir.path() / "recording.json", json_with("cms.wav", "cms.csv"));
  write(dir.path() / "cms.csv", "t_s,point1,tacho\n0,1,0\n0.25,inf,0\n");

  // Act
  const auto result = hal::read_bundle(dir.path());

  // Assert
  ASSERT_FALSE(result);
  EXPECT_EQ(result.error.field, "line 3, column 'point1'") << result.error.to_string();
  EXPECT_NE(result.error.message.find("finite"), std::string::npos);
}

TEST(RecordingBundle, RejectsCsvTimesThatDisagreeWithTheSampleRate) {
  // Arrange: 4 Hz means 0.25 s steps; the second row says 1.0 s
  TempDir dir;
  write(dir.path() / "recording.json", json_with("cms.wav", "cms.csv"));
  write(dir.path() / "cms.csv", "t_s,point1,tacho\n0,1,0\n1.0,1,0\n");

  // Act
  const auto result = hal::read_bundle(dir.path());

  // Assert
  ASSERT_FALSE(result);
  EXPECT_EQ(result.error.field, "line 3, column 't_s'");
  EXPECT_NE(result.error.message.find("expected 0.25"), std::string::npos)
      << result.error.to_string();
}

TEST(RecordingBundle, RejectsAScadaCsvWithoutWindSpeed) {
  // Arrange
  TempDir dir;
  write(dir.path() / "recording.json", kJson);
  write(dir.path() / "cms.wav", kGoodWav);
  write(dir.path() / "scada.csv", "t_s,power_kw\n0,500\n");

  // Act
  const auto result = hal::read_bundle(dir.path());

  // Assert
  ASSERT_FALSE(result);
  EXPECT_NE(result.error.file.find("scada.csv"), std::string::npos);
  EXPECT_NE(result.error.message.find("wind_speed_mps"), std::string::npos)
      << result.error.to_string();
}

TEST(RecordingBundle, RejectsScadaTimesThatDoNotIncrease) {
  // Arrange
  TempDir dir;
  write(dir.path() / "recording.json", kJson);
  write(dir.path() / "cms.wav", kGoodWav);
  write(dir.path() / "scada.csv", "t_s,wind_speed_mps\n0,5\n10,5\n10,6\n");

  // Act
  const auto result = hal::read_bundle(dir.path());

  // Assert
  ASSERT_FALSE(result);
  EXPECT_EQ(result.error.field, "row 3 (line 4), column 't_s'") << result.error.to_string();
}

TEST(RecordingBundle, RejectsAScadaRowWithoutWindSpeedNamingRowLineAndColumn) {
  // Arrange: the wind cell of the second data row is empty
  TempDir dir;
  write(dir.path() / "recording.json", kJson);
  write(dir.path() / "cms.wav", kGoodWav);
  write(dir.path() / "scada.csv", "t_s,wind_speed_mps\n0,5\n10,\n");

  // Act
  const auto result = hal::read_bundle(dir.path());

  // Assert
  ASSERT_FALSE(result);
  EXPECT_EQ(result.error.field, "row 2 (line 3), column 'wind_speed_mps'")
      << result.error.to_string();
  EXPECT_NE(result.error.file.find("scada.csv"), std::string::npos);
}

TEST(RecordingBundle, WriterLeavesNothingBehindWhenASampleIsNotFinite) {
  // Arrange
  TempDir dir;
  hal::Recording bad = sample_recording("cms.wav");
  bad.samples[1][42] = std::numeric_limits<double>::infinity();
  const fs::path target = dir.path() / "new-bundle";

  // Act
  const auto err = hal::write_bundle(target, bad);

  // Assert
  ASSERT_TRUE(err);
  EXPECT_EQ(err->field, "point2 sample 42");
  EXPECT_FALSE(fs::exists(target));
}

TEST(RecordingBundle, WriterRefusesMismatchedChannelCountAndKeepsAnOldBundleIntact) {
  // Arrange: a good bundle on disk, then an attempt to overwrite it with 3 channels of names but 2
  // of data
  TempDir dir;
  ASSERT_FALSE(hal::write_bundle(dir.path(), sample_recording("cms.wav")));
  const std::string before = slurp(dir.path() / "recording.json");
  hal::Recording bad = sample_recording("cms.wav");
  bad.channels.push_back({"point3", "b6", "radial", "", "m/s^2"});

  // Act
  const auto err = hal::write_bundle(dir.path(), bad);

  // Assert
  ASSERT_TRUE(err);
  EXPECT_NE(err->message.find("expected 3"), std::string::npos) << err->to_string();
  EXPECT_EQ(slurp(dir.path() / "recording.json"), before);
}

TEST(RecordingBundle, WriterRejectsAnOperatingPointOutsideTheGivenRange) {
  // Arrange
  TempDir dir;
  hal::Recording r = sample_recording("cms.csv");
  r.operating_point.rotor_speed_rpm = 20.0;
  hal::OperatingRange range;
  range.max_rotor_speed_rpm = 17.76;

  // Act
  const auto err = hal::write_bundle(dir.path() / "x", r, range);

  // Assert
  ASSERT_TRUE(err);
  EXPECT_EQ(err->file, "recording.json");
  EXPECT_EQ(err->field, "operating_point.rotor_speed_rpm");
  EXPECT_FALSE(fs::exists(dir.path() / "x"));
}

}  // namespace
