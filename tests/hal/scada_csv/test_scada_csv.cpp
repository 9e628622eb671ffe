// Streaming SCADA CSV reader: the bundle's scada.csv, the Kelmarsh export through
// its column mapping, and an error naming file / row / column for each bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "hal/scada_csv.hpp"

namespace {

using hal::ScadaQuantity;
using hal::ScadaReadResult;

class ScadaCsv : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("drivetwin_scada_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    const auto path = dir_ / name;
    std::ofstream(path, std::ios::binary) << text;
    return path.string();
  }
  std::filesystem::path dir_;
};

TEST_F(ScadaCsv, ReadsTheBundleFormatRowByRowWithOptionalColumnsAbsent) {
  // Arrange: torque_nm and pitch_deg are missing (allowed by recording-bundle.md).
  const std::string path = write("scada.csv",
                                 "t_s,wind_speed_mps,rotor_speed_rpm,power_kw\n"
                                 "0,6.75,8.33,300.5\n"
                                 "\n"
                                 "600,7.5,9.0,\n");
  hal::ScadaCsvReader reader;
  ASSERT_TRUE(reader.open(path, hal::bundle_scada_columns())) << reader.error();
  hal::ScadaRow row;
  // Act / Assert: first row
  ASSERT_EQ(reader.next(row), ScadaReadResult::kRow) << reader.error();
  EXPECT_EQ(row.row, 1u);
  EXPECT_DOUBLE_EQ(row.get(ScadaQuantity::kWindSpeed), 6.75);
  EXPECT_DOUBLE_EQ(row.get(ScadaQuantity::kRotorSpeed), 8.33);
  EXPECT_DOUBLE_EQ(row.get(ScadaQuantity::kPower), 300.5);
  EXPECT_FALSE(row.has(ScadaQuantity::kRotorTorque));
  EXPECT_FALSE(reader.has_column(ScadaQuantity::kPitch));
  // second row: blank line skipped, empty power cell absent
  ASSERT_EQ(reader.next(row), ScadaReadResult::kRow) << reader.error();
  EXPECT_EQ(row.row, 2u);
  EXPECT_EQ(row.line, 4u);
  EXPECT_DOUBLE_EQ(row.time_s(), 600.0);
  EXPECT_FALSE(row.has(ScadaQuantity::kPower));
  EXPECT_TRUE(std::isnan(row.get(ScadaQuantity::kPower)));
  EXPECT_EQ(reader.next(row), ScadaReadResult::kEnd);
}

TEST_F(ScadaCsv, ReadsKelmarshColumnsWithDegreeSignsAndDateTimes) {
  // Arrange: the Kelmarsh header (UTF-8 "°") with quoted fields and CRLF endings.
  const std::string path =
      write("k.csv",
            "Date and time,Wind speed (m/s),Rotor speed (RPM),Pitch angle (\u00b0),Power (kW)\r\n"
            "2019-01-01 00:10:00,4.33,8.86,\"0.06\",189.5\r\n");
  hal::ScadaCsvReader reader;
  ASSERT_TRUE(reader.open(path, hal::kelmarsh_scada_columns())) << reader.error();
  hal::ScadaRow row;
  // Act
  ASSERT_EQ(reader.next(row), ScadaReadResult::kRow) << reader.error();
  // Assert: 2019-01-01 is day 17 897 after 1970-01-01 (49 years, 12 leap days):
  // 17 897·86 400 s + 600 s = 1 546 301 400 s.
  EXPECT_DOUBLE_EQ(row.time_s(), 1546301400.0);
  EXPECT_DOUBLE_EQ(row.get(ScadaQuantity::kPitch), 0.06);
  EXPECT_DOUBLE_EQ(row.get(ScadaQuantity::kPower), 189.5);
}

TEST_F(ScadaCsv, ReadsKelmarshAmbientTemperatureAndYawErrorAndNamesABadCell) {
  // Arrange: the two optional columns of the Kelmarsh export; the second row's
  // temperature is text.
  const std::string path = write(
      "k.csv",
      "Date and time,Wind speed (m/s),Nacelle ambient temperature (\u00b0C),Yaw error (\u00b0)\n"
      "2019-01-01 00:10:00,4.33,9.01,-7.5\n"
      "2019-01-01 00:20:00,4.40,warm,1.0\n");
  hal::ScadaCsvReader reader;
  ASSERT_TRUE(reader.open(path, hal::kelmarsh_scada_columns())) << reader.error();
  hal::ScadaRow row;
  // Act / Assert
  ASSERT_EQ(reader.next(row), ScadaReadResult::kRow) << reader.error();
  EXPECT_DOUBLE_EQ(row.get(ScadaQuantity::kAmbientTemperature), 9.01);
  EXPECT_DOUBLE_EQ(row.get(ScadaQuantity::kYawError), -7.5);
  ASSERT_EQ(reader.next(row), ScadaReadResult::kError);
  EXPECT_NE(reader.error().find("row 2 (line 3), column 'Nacelle ambient temperature (\u00b0C)': "
                                "'warm' is not a number"),
            std::string::npos)
      << reader.error();
}

TEST_F(ScadaCsv, BundleFileWithoutTheOptionalExtensionsHasThemAbsent) {
  const std::string path = write("scada.csv", "t_s,wind_speed_mps\n0,5\n");
  hal::ScadaCsvReader reader;
  ASSERT_TRUE(reader.open(path, hal::bundle_scada_columns())) << reader.error();
  hal::ScadaRow row;
  ASSERT_EQ(reader.next(row), ScadaReadResult::kRow) << reader.error();
  EXPECT_FALSE(reader.has_column(ScadaQuantity::kAmbientTemperature));
  EXPECT_FALSE(row.has(ScadaQuantity::kYawError));
}

TEST_F(ScadaCsv, CustomMappingRenamesOnlyTheNamedFields) {
  std::string error;
  const auto columns = hal::parse_scada_columns("wind_speed_mps=WS; power_kw = P (kW)", &error);
  ASSERT_TRUE(columns) << error;
  EXPECT_EQ(columns->quantity[static_cast<std::size_t>(hal::ScadaQuantity::kWindSpeed)], "WS");
  EXPECT_EQ(columns->quantity[static_cast<std::size_t>(hal::ScadaQuantity::kPower)], "P (kW)");
  EXPECT_EQ(columns->quantity[static_cast<std::size_t>(hal::ScadaQuantity::kRotorSpeed)],
            "rotor_speed_rpm");
  EXPECT_EQ(columns->time, "t_s");
}

TEST_F(ScadaCsv, UnknownFieldInAMappingIsNamed) {
  std::string error;
  EXPECT_FALSE(hal::parse_scada_columns("windspeed=WS", &error));
  EXPECT_NE(error.find("unknown field 'windspeed'"), std::string::npos) << error;
}

TEST_F(ScadaCsv, MissingRequiredColumnNamesTheFileAndTheColumn) {
  const std::string path = write("scada.csv", "t_s,rotor_speed_rpm\n0,8\n");
  hal::ScadaCsvReader reader;
  EXPECT_FALSE(reader.open(path, hal::bundle_scada_columns()));
  EXPECT_NE(reader.error().find(path), std::string::npos) << reader.error();
  EXPECT_NE(reader.error().find("missing column 'wind_speed_mps'"), std::string::npos)
      << reader.error();
}

TEST_F(ScadaCsv, NonNumericValueNamesFileRowAndColumn) {
  const std::string path = write("scada.csv",
                                 "t_s,wind_speed_mps,rotor_speed_rpm\n"
                                 "0,6,8\n"
                                 "600,six,8\n");
  hal::ScadaCsvReader reader;
  ASSERT_TRUE(reader.open(path, hal::bundle_scada_columns()));
  hal::ScadaRow row;
  ASSERT_EQ(reader.next(row), ScadaReadResult::kRow);
  EXPECT_EQ(reader.next(row), ScadaReadResult::kError);
  EXPECT_NE(reader.error().find(path +
                                ": row 2 (line 3), column 'wind_speed_mps': 'six' is not a number"),
            std::string::npos)
      << reader.error();
}

TEST_F(ScadaCsv, NonFiniteValueIsAnError) {
  for (const char* bad : {"nan", "inf", "-inf", "NaN"}) {
    const std::string path =
        write("scada.csv", std::string("t_s,wind_speed_mps,rotor_speed_rpm\n0,6,") + bad + "\n");
    hal::ScadaCsvReader reader;
    ASSERT_TRUE(reader.open(path, hal::bundle_scada_columns()));
    hal::ScadaRow row;
    EXPECT_EQ(reader.next(row), ScadaReadResult::kError) << bad;
    EXPECT_NE(reader.error().find("column 'rotor_speed_rpm'"), std::string::npos) << reader.error();
    EXPECT_NE(reader.error().find("not a finite number"), std::string::npos) << reader.error();
  }
}

TEST_F(ScadaCsv, WrongFieldCountAndBadTimeAreErrors) {
  const std::string path = write("scada.csv",
                                 "t_s,wind_speed_mps\n"
                                 "0,6,7\n");
  hal::ScadaCsvReader reader;
  ASSERT_TRUE(reader.open(path, hal::bundle_scada_columns()));
  hal::ScadaRow row;
  EXPECT_EQ(reader.next(row), ScadaReadResult::kError);
  EXPECT_NE(reader.error().find("row 1 (line 2): 3 fields, expected 2"), std::string::npos)
      << reader.error();

  const std::string path2 = write("scada2.csv", "t_s,wind_speed_mps\n2019-13-01 00:00:00,6\n");
  ASSERT_TRUE(reader.open(path2, hal::bundle_scada_columns()));
  EXPECT_EQ(reader.next(row), ScadaReadResult::kError);
  EXPECT_NE(reader.error().find("column 't_s'"), std::string::npos) << reader.error();
}

TEST_F(ScadaCsv, ReadsCsvTextHeldInMemoryUnderTheGivenName) {
  hal::ScadaCsvReader reader;
  ASSERT_TRUE(reader.open_text("t_s,wind_speed_mps\n0,5\n600,x\n", "<built-in day.csv>",
                               hal::bundle_scada_columns()));
  hal::ScadaRow row;
  ASSERT_EQ(reader.next(row), ScadaReadResult::kRow);
  EXPECT_DOUBLE_EQ(row.get(ScadaQuantity::kWindSpeed), 5.0);
  EXPECT_EQ(reader.next(row), ScadaReadResult::kError);
  EXPECT_NE(reader.error().find("<built-in day.csv>: row 2 (line 3)"), std::string::npos)
      << reader.error();
}

TEST_F(ScadaCsv, MissingFileIsReportedNotThrown) {
  hal::ScadaCsvReader reader;
  EXPECT_FALSE(reader.open((dir_ / "nope.csv").string(), hal::bundle_scada_columns()));
  EXPECT_NE(reader.error().find("cannot open"), std::string::npos);
}

TEST_F(ScadaCsv, StreamsTheRealKelmarshFileWithoutErrors) {
  const std::string path = DRIVETWIN_SHARED_DIR "/data/kelmarsh/kelmarsh-t1-2019.csv";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data absent: " << path;
  hal::ScadaCsvReader reader;
  ASSERT_TRUE(reader.open(path, hal::kelmarsh_scada_columns())) << reader.error();
  hal::ScadaRow row;
  std::size_t rows = 0;
  ScadaReadResult r;
  while ((r = reader.next(row)) == ScadaReadResult::kRow) ++rows;
  EXPECT_EQ(r, ScadaReadResult::kEnd) << reader.error();
  EXPECT_EQ(rows, 10305u);  // shared/data/README.md
}

}  // namespace
