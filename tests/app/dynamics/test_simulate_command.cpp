// `drivetwin simulate` end to end, in process (as main() runs it), into a temporary
// directory: the bundle it writes reads back as a valid recording with the channels,
// rate and sample count asked for; loads.csv has one row per sample and the columns
// it documents; the mean mesh forces equal the torque each stage passes divided by
// its base radius (hand calculation from the tooth counts of drivetrain-2mw.md); the
// tacho pulses once per hss revolution; bad arguments are refused with a message
// naming the option, and nothing is written. CMakeLists.txt also runs the real
// executable on a bad argument and expects a non-zero exit status.
#include <gtest/gtest.h>

#include <unistd.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "cli/run.hpp"
#include "hal/recording_bundle.hpp"
#include "support/run_command.hpp"

namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;

// The paper's operating point (drivetrain-2mw.md).
constexpr double kRpm = 8.33;
constexpr double kTorqueNm = 361747.0;
constexpr double kRateHz = 25600.0;

fs::path scratch_dir(const std::string& name) {
  const fs::path p =
      fs::temp_directory_path() / ("drivetwin-test-simulate-" + std::to_string(::getpid())) / name;
  fs::remove_all(p);
  return p;
}

// Runs `drivetwin simulate <args>` as main() would.
test_support::CommandResult run_simulate(std::vector<std::string> args) {
  args.insert(args.begin(), "simulate");
  return test_support::run_command(args);
}

std::string number(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
};

Csv read_csv(const fs::path& file) {
  Csv csv;
  std::ifstream in(file);
  std::string line;
  if (!std::getline(in, line)) return csv;
  std::stringstream h(line);
  for (std::string cell; std::getline(h, cell, ',');) csv.header.push_back(cell);
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::stringstream r(line);
    for (std::string cell; std::getline(r, cell, ',');) row.push_back(std::stod(cell));
    csv.rows.push_back(std::move(row));
  }
  return csv;
}

double column_mean(const Csv& csv, const std::string& name) {
  const auto it = std::find(csv.header.begin(), csv.header.end(), name);
  if (it == csv.header.end()) {
    ADD_FAILURE() << "loads.csv has no column " << name;
    return 0.0;
  }
  const auto c = static_cast<std::size_t>(it - csv.header.begin());
  double sum = 0.0;
  for (const auto& row : csv.rows) sum += row.at(c);
  return sum / static_cast<double>(csv.rows.size());
}

TEST(SimulateCommand, WritesABundleAndLoadsWhoseMeanMeshForcesEqualStageTorqueOverBaseRadius) {
  // Arrange: seven planetary mesh periods (13.745 Hz = rotor frequency × z_ring), so the
  // mean over the run is a mean over whole cycles of the slowest mesh.
  const double f_rotor_hz = kRpm / 60.0;
  const double seconds = 7.0 / (f_rotor_hz * 99.0);
  const std::size_t samples = static_cast<std::size_t>(std::llround(seconds * kRateHz));
  // Hand calculation (as in the model's statics test): ring fixed, T_sun = T·z_s/(z_s+z_r),
  // T_ring = T·z_r/(z_s+z_r), spur planetary stage (m = 17 mm, α = 20°): per planet
  // F = T_gear / (3·r_b), r_b = z·m/2·cos α; helical stages (m_n = 14 mm, β = 10°):
  // F_n = T_pinion / (r_b,pinion·cos β_b), α_t = atan(tan α / cos β), β_b = atan(tan β·cos α_t).
  const double cos20 = std::cos(20 * kPi / 180);
  const double t_sun = kTorqueNm * 21.0 / 120.0;
  const double f_sun_planet = t_sun / (3 * 21 * 0.017 / 2 * cos20);
  const double f_ring_planet = kTorqueNm * 99.0 / 120.0 / (3 * 99 * 0.017 / 2 * cos20);
  const double beta = 10 * kPi / 180;
  const double mt = 0.014 / std::cos(beta);
  const double at = std::atan(std::tan(20 * kPi / 180) / std::cos(beta));
  const double bb = std::atan(std::tan(beta) * std::cos(at));
  const double t_ims = t_sun * 21.0 / 92.0;
  const double t_hss = t_ims * 26.0 / 107.0;
  const double f_intermediate = t_ims / (21 * mt / 2 * std::cos(at) * std::cos(bb));
  const double f_high_speed = t_hss / (26 * mt / 2 * std::cos(at) * std::cos(bb));
  // hss speed = rotor × (1 + z_r/z_s) × 92/21 × 107/26.
  const double hss_revolutions =
      f_rotor_hz * (120.0 / 21.0) * (92.0 / 21.0) * (107.0 / 26.0) * seconds;
  const fs::path dir = scratch_dir("paper-point");

  // Act
  const std::string error = run_simulate({"--rpm", number(kRpm), "--torque", number(kTorqueNm),
                                          "--seconds", number(seconds), "--out", dir.string()})
                                .error;

  // Assert: the bundle.
  ASSERT_EQ(error, "");
  EXPECT_EQ(app::cli::exit_status(), 0);
  const hal::BundleReadResult bundle = hal::read_bundle(dir);
  ASSERT_TRUE(bundle) << bundle.error.to_string();
  const hal::Recording& rec = *bundle.recording;
  EXPECT_EQ(rec.sample_rate_hz, kRateHz);
  ASSERT_EQ(rec.channels.size(), 3u);
  EXPECT_EQ(rec.channels[0].name, "point1");
  EXPECT_EQ(rec.channels[1].name, "point2");
  EXPECT_EQ(rec.channels[2].name, "tacho");
  EXPECT_EQ(rec.sample_count(), samples);
  EXPECT_DOUBLE_EQ(rec.operating_point.rotor_speed_rpm, kRpm);
  EXPECT_DOUBLE_EQ(rec.operating_point.input_torque_nm.value_or(-1.0), kTorqueNm);
  // The tacho: one rising edge per completed hss revolution (it starts high, at angle 0).
  int rising = 0;
  for (std::size_t i = 1; i < rec.samples[2].size(); ++i)
    rising += rec.samples[2][i] > 2.5 && rec.samples[2][i - 1] < 2.5;
  EXPECT_EQ(rising, static_cast<int>(std::floor(hss_revolutions)));
  // The seat accelerations vibrate (a gearbox under load is not silent) and are finite.
  double rms1 = 0.0;
  for (double a : rec.samples[0]) rms1 += a * a;
  EXPECT_GT(std::sqrt(rms1 / static_cast<double>(samples)), 0.0);

  // Assert: loads.csv — columns, one row per sample at t = (i+1)/rate, and the statics.
  const Csv loads = read_csv(dir / "loads.csv");
  std::vector<std::string> expected_header{"t_s"};
  for (const char* m : {"sun_planet_1", "sun_planet_2", "sun_planet_3", "ring_planet_1",
                        "ring_planet_2", "ring_planet_3", "intermediate", "high_speed"}) {
    expected_header.push_back(std::string(m) + "_n");
  }
  for (int b = 1; b <= 6; ++b) {
    for (const char* c : {"_x_n", "_y_n", "_radial_n"})
      expected_header.push_back("b" + std::to_string(b) + c);
  }
  EXPECT_EQ(loads.header, expected_header);
  ASSERT_EQ(loads.rows.size(), samples);
  for (const auto& row : loads.rows) ASSERT_EQ(row.size(), expected_header.size());
  EXPECT_NEAR(loads.rows.front()[0], 1.0 / kRateHz, 1e-8);
  EXPECT_NEAR(loads.rows.back()[0], static_cast<double>(samples) / kRateHz, 1e-8);
  double sum_sun_planet = 0.0, sum_ring_planet = 0.0;
  for (int n = 1; n <= 3; ++n) {
    sum_sun_planet += column_mean(loads, "sun_planet_" + std::to_string(n) + "_n");
    sum_ring_planet += column_mean(loads, "ring_planet_" + std::to_string(n) + "_n");
  }
  EXPECT_NEAR(sum_sun_planet / 3 / f_sun_planet, 1.0, 0.01);
  EXPECT_NEAR(sum_ring_planet / 3 / f_ring_planet, 1.0, 0.01);
  EXPECT_NEAR(column_mean(loads, "intermediate_n") / f_intermediate, 1.0, 0.01);
  EXPECT_NEAR(column_mean(loads, "high_speed_n") / f_high_speed, 1.0, 0.01);
  fs::remove_all(dir);
}

TEST(SimulateCommand, FullModelWritesTheSameColumnsAndSampleCount) {
  // Arrange: a short run (the full model is the slow reference).
  const fs::path dir = scratch_dir("full");
  const double seconds = 0.01;
  // Act
  const std::string error =
      run_simulate({"--rpm", number(kRpm), "--torque", number(kTorqueNm), "--seconds",
                    number(seconds), "--run-in", "0.005", "--out", dir.string(), "--full"})
          .error;
  // Assert
  ASSERT_EQ(error, "");
  const hal::BundleReadResult bundle = hal::read_bundle(dir);
  ASSERT_TRUE(bundle) << bundle.error.to_string();
  EXPECT_EQ(bundle.recording->sample_count(),
            static_cast<std::size_t>(std::llround(seconds * kRateHz)));
  EXPECT_NE(bundle.recording->notes.find("full-order"), std::string::npos)
      << bundle.recording->notes;
  const Csv loads = read_csv(dir / "loads.csv");
  EXPECT_EQ(loads.header.size(), 1u + 8u + 18u);
  EXPECT_EQ(loads.rows.size(), bundle.recording->sample_count());
  fs::remove_all(dir);
}

// RMS about the mean of x[from, from + n).
double rms(const std::vector<double>& x, std::size_t from, std::size_t n) {
  double m = 0.0, e = 0.0;
  for (std::size_t i = from; i < from + n; ++i) m += x[i];
  m /= static_cast<double>(n);
  for (std::size_t i = from; i < from + n; ++i) e += (x[i] - m) * (x[i] - m);
  return std::sqrt(e / static_cast<double>(n));
}

TEST(SimulateCommand, DiscardsTheStartUpTransientByDefaultAndSaysSo) {
  // Arrange: 1 s at the paper point, default run-in. A recording at a constant operating
  // point is stationary: the first and the last quarter second have the same RMS, and no
  // start-up peak (the issue measured point2 at 0.85 m/s² RMS over the first 0.5 s of a
  // static start against 0.27 settled, peak 18.3 against 1.5).
  const fs::path dir = scratch_dir("settled");
  const test_support::CommandResult r =
      run_simulate({"--rpm", number(kRpm), "--torque", number(kTorqueNm), "--seconds", "1",
                    "--no-loads", "--out", dir.string()});
  const std::string& out = r.out;
  // Assert
  ASSERT_EQ(r.error, "");
  EXPECT_NE(out.find("run-in: the first 1.84"), std::string::npos) << out;  // ln(100)·2/5 s
  const hal::BundleReadResult bundle = hal::read_bundle(dir);
  ASSERT_TRUE(bundle) << bundle.error.to_string();
  const hal::Recording& rec = *bundle.recording;
  EXPECT_NE(rec.notes.find("after a run-in of 1.84"), std::string::npos) << rec.notes;
  const std::size_t q = rec.sample_count() / 4;
  for (std::size_t c = 0; c < 2; ++c) {
    const std::vector<double>& x = rec.samples[c];
    EXPECT_NEAR(rms(x, 0, q) / rms(x, x.size() - q, q), 1.0, 0.15) << rec.channels[c].name;
    double peak_first = 0.0, peak_last = 0.0;
    for (std::size_t i = 0; i < q; ++i) peak_first = std::max(peak_first, std::fabs(x[i]));
    for (std::size_t i = x.size() - q; i < x.size(); ++i)
      peak_last = std::max(peak_last, std::fabs(x[i]));
    EXPECT_LT(peak_first, 1.5 * peak_last) << rec.channels[c].name;
  }
  EXPECT_FALSE(fs::exists(dir / "loads.csv"));
  fs::remove_all(dir);
}

TEST(SimulateCommand, LoadsCanBeDecimated) {
  // Arrange: 0.1 s, every 10th sample.
  const fs::path dir = scratch_dir("decimated");
  const test_support::CommandResult r =
      run_simulate({"--rpm", number(kRpm), "--torque", number(kTorqueNm), "--seconds", "0.1",
                    "--run-in", "0.01", "--loads-every", "10", "--out", dir.string()});
  const std::string& out = r.out;
  // Assert: 2560 samples → 256 rows at t = 10/fs, 20/fs, ...
  ASSERT_EQ(r.error, "");
  EXPECT_NE(out.find("every 10-th sample (2560 Hz"), std::string::npos) << out;
  const Csv loads = read_csv(dir / "loads.csv");
  ASSERT_EQ(loads.rows.size(), 256u);
  EXPECT_NEAR(loads.rows[1][0] - loads.rows[0][0], 10.0 / kRateHz, 1e-8);
  fs::remove_all(dir);
}

TEST(SimulateCommand, RefusesBadArgumentsWithAMessageNamingTheOptionAndWritesNothing) {
  struct Bad {
    std::vector<std::string> args;
    const char* expected;
  };
  const fs::path dir = scratch_dir("bad");
  const std::string out = dir.string();
  for (const Bad& bad :
       {Bad{{"--rpm", "-5", "--torque", "1000", "--out", out},
            "--rpm: -5 is out of range; expected a number > 0 [rpm]"},
        Bad{{"--rpm", "8.33", "--torque", "-1", "--out", out}, "--torque: -1 is out of range"},
        Bad{{"--rpm", "8.33", "--torque", "1e9", "--out", out}, "--torque: 1000000000"},
        Bad{{"--rpm", "30", "--torque", "1000", "--out", out}, "--rpm: 30"},
        Bad{{"--rpm", "8.33", "--torque", "1000", "--seconds", "0", "--out", out}, "--seconds"},
        Bad{{"--rpm", "8.33", "--torque", "1000", "--rate", "0", "--out", out}, "--rate"},
        Bad{{"--rpm", "8.33", "--torque", "1000", "--rate", "100", "--out", out},
            "--rate: 100 Hz cannot represent this simulation"},
        Bad{{"--rpm", "8.33", "--torque", "1000", "--loads-every", "0", "--out", out},
            "--loads-every: 0 is out of range"},
        Bad{{"--rpm", "8.33", "--torque", "1000", "--run-in", "-1", "--out", out},
            "--run-in: -1 is out of range"},
        Bad{{"--rpm", "8.33", "--torque", "1000", "--out", out, "--drivetrain", "no-such.toml"},
            "--drivetrain"}}) {
    // Act
    const test_support::CommandResult r = run_simulate(bad.args);
    // Assert
    EXPECT_NE(r.exit_code, 0) << bad.expected;
    EXPECT_NE(r.error.find(bad.expected), std::string::npos)
        << "expected '" << bad.expected << "' in: " << r.error;
    EXPECT_FALSE(fs::exists(dir)) << bad.expected;
  }
}

}  // namespace
