// Replay backends against recordings built here with known content: blocks
// carry exactly the recorded samples at their recorded times, the tacho channel
// gives back the shaft speed it was synthesised with, SCADA rows appear when
// their time comes and go stale between rows.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "../no_alloc.hpp"
#include "hal/replay_backends.hpp"

namespace {

using namespace std::chrono_literals;
using hal::Status;

/// 2 vibration channels + a tacho at fs; point1[i] = i, point2[i] = −i; tacho:
/// a 1 V pulse of 10 % duty at f_tacho.
hal::Recording recording(double fs, std::size_t n, double f_tacho) {
  hal::Recording r;
  r.sample_rate_hz = fs;
  r.channels = {{"point1", "b5", "radial", "", "m/s^2"},
                {"tacho", "hss", "", "once_per_rev", "V"},
                {"point2", "b3", "radial", "", "m/s^2"}};
  r.operating_point.rotor_speed_rpm = 8.33;
  r.operating_point.input_torque_nm = 361747.0;
  r.samples.assign(3, std::vector<double>(n));
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / fs;
    r.samples[0][i] = static_cast<double>(i);
    r.samples[2][i] = -static_cast<double>(i);
    const double phase = t * f_tacho - std::floor(t * f_tacho);
    r.samples[1][i] = phase > 0.5 && phase < 0.6 ? 1.0 : 0.0;
  }
  return r;
}

TEST(ReplayCmsStream, DeliversRecordedSamplesInBlocksWhenTheirLastSampleIsDue) {
  // Arrange: 100 samples at 1 kHz → 3 full blocks of 28 per channel (the last 16 samples are not
  // sent)
  const hal::Recording rec = recording(1000.0, 100, 10.0);
  hal::ReplayClock clock;  // stepped
  hal::ReplayCmsStream cms(rec, clock);
  ASSERT_EQ(cms.configure(), Status::kOk);
  ASSERT_EQ(cms.activate(), Status::kOk);
  hal::CmsBlock b;

  // Act / Assert: block 0 holds samples 0..27, due at t = 27 ms
  clock.advance(26ms);
  EXPECT_EQ(cms.read(b), Status::kNoData);
  clock.advance(1ms);
  ASSERT_EQ(cms.read(b), Status::kOk);
  EXPECT_EQ(b.channel, 0);
  EXPECT_EQ(b.sequence, 0);
  EXPECT_EQ(b.count, 28);
  EXPECT_EQ(b.samples[27], 27.0f);
  ASSERT_EQ(cms.read(b), Status::kOk);  // the same block of point2 (tacho left out)
  EXPECT_EQ(b.channel, 1);
  EXPECT_EQ(cms.source_channel(1), 2u);
  EXPECT_EQ(b.samples[5], -5.0f);
  EXPECT_EQ(cms.read(b), Status::kNoData);

  clock.advance(1s);
  std::vector<hal::CmsBlock> rest;
  Status s;
  while ((s = cms.read(b)) == Status::kOk) rest.push_back(b);
  EXPECT_EQ(s, Status::kEndOfData);
  ASSERT_EQ(rest.size(), 4u);
  EXPECT_EQ(rest[2].sequence, 2);
  EXPECT_EQ(rest[2].samples[0], 56.0f);
  EXPECT_EQ(rest[2].stamp, 56ms);
  EXPECT_EQ(cms.health(clock.now()), Status::kEndOfData);
}

TEST(ReplayKeyphasor, GivesBackTheShaftSpeedTheTachoWasRecordedAt) {
  // Arrange: hss at the paper point, 14.3032 Hz, sampled at 25.6 kHz for 1 s
  const hal::Recording rec = recording(25600.0, 25600, 14.3032);
  hal::ReplayClock clock;
  hal::ReplayKeyphasor kp(rec, clock);
  ASSERT_EQ(kp.configure(), Status::kOk);
  ASSERT_EQ(kp.activate(), Status::kOk);
  hal::KeyphasorTracker tracker;

  // Act: play the whole second in 10 ms loop steps
  for (int i = 0; i < 100; ++i) {
    clock.advance(10ms);
    hal::KeyphasorEdge e;
    while (kp.read(e) == Status::kOk) tracker.on_edge(e);
  }
  const auto s = tracker.state(clock.now());

  // Assert: 14 edges; interpolated edge times give the speed within 0.1 %
  EXPECT_EQ(kp.edges(), 14u);
  ASSERT_TRUE(s.valid);
  EXPECT_NEAR(s.speed_hz, 14.3032, 14.3032e-3);
}

TEST(TachoEdges, InterpolateTheThresholdCrossingBetweenSamples) {
  // Arrange: 0, 0, 0.25, 0.75, 1 at fs = 4 Hz → threshold 0.5 crossed halfway between samples 2 and
  // 3
  const std::vector<double> x{0, 0, 0.25, 0.75, 1, 1, 0, 0};

  // Act
  const auto e = hal::tacho_edges_s(x, 4.0);

  // Assert
  ASSERT_EQ(e.size(), 1u);
  EXPECT_DOUBLE_EQ(e[0], 2.5 / 4.0);
}

TEST(ReplayScadaSource, ShowsEachBundleRowFromItsTimeAndGoesStaleAfterTheLast) {
  // Arrange: rows at 0, 10, 20 s → automatic stale limit 2 × 10 s
  std::vector<hal::BundleScadaRow> rows{{0.0, 5.0, 8.0, std::nullopt, std::nullopt, std::nullopt},
                                        {10.0, 6.0, 8.2, std::nullopt, std::nullopt, std::nullopt},
                                        {20.0, 7.0, 8.4, std::nullopt, std::nullopt, 300000.0}};
  hal::ReplayScadaSource src(rows);
  ASSERT_EQ(src.configure(), Status::kOk);
  ASSERT_EQ(src.activate(), Status::kOk);
  hal::ScadaData d;

  // Act / Assert
  EXPECT_EQ(src.read(9999ms, d), Status::kOk);
  EXPECT_EQ(d[hal::ScadaQuantity::kWindSpeed].value, 5.0);
  EXPECT_EQ(src.read(10s, d), Status::kOk);
  EXPECT_EQ(d[hal::ScadaQuantity::kWindSpeed].value, 6.0);
  EXPECT_FALSE(d[hal::ScadaQuantity::kRotorTorque].valid);
  EXPECT_EQ(src.read(25s, d), Status::kOk);
  EXPECT_EQ(d[hal::ScadaQuantity::kRotorTorque].value, 300000.0);
  EXPECT_EQ(src.read(41s, d), Status::kEndOfData);
  EXPECT_EQ(src.read(5s, d), Status::kOk);  // replay restarted: back to row 0
  EXPECT_EQ(d[hal::ScadaQuantity::kWindSpeed].value, 5.0);
}

TEST(ReplayScadaSource, ReplaysAKelmarshStyleExportFromItsDateTimes) {
  // Arrange: 10-minute rows with the Kelmarsh header (UTF-8 degree sign) and one empty wind cell
  const auto path = std::filesystem::temp_directory_path() /
                    ("drivetwin-kelmarsh-" + std::to_string(::getpid()) + ".csv");
  {
    std::ofstream out(path);
    out << "Date and time,Wind speed (m/s),Rotor speed (RPM),Pitch angle (°),Power (kW)\n"
        << "2019-01-01 00:00:00,6.5,11.0,0.1,500\n"
        << "2019-01-01 00:10:00,,11.2,0.1,510\n"
        << "2019-01-01 00:20:00,7.5,11.4,0.2,620\n";
  }
  hal::ReplayScadaSource src(path.string(), hal::kelmarsh_scada_columns());

  // Act
  const Status configured = src.configure();
  ASSERT_EQ(src.activate(), Status::kOk);
  hal::ScadaData d;
  const Status at_20min = src.read(20min, d);
  std::filesystem::remove(path);

  // Assert: the row without wind is skipped; 20 min after the first row is the third
  ASSERT_EQ(configured, Status::kOk) << src.error();
  EXPECT_EQ(src.rows(), 2u);
  EXPECT_EQ(src.skipped_rows(), 1u);
  EXPECT_EQ(at_20min, Status::kOk);
  EXPECT_EQ(d[hal::ScadaQuantity::kWindSpeed].value, 7.5);
  EXPECT_EQ(d[hal::ScadaQuantity::kPower].value, 620.0);
}

TEST(ReplayScadaSource, NamesTheFileWhenItCannotBeRead) {
  hal::ReplayScadaSource src("no/such/scada.csv", hal::bundle_scada_columns());
  EXPECT_EQ(src.configure(), Status::kInvalidConfig);
  EXPECT_NE(src.error().find("no/such/scada.csv"), std::string::npos) << src.error();
}

TEST(ReplayBackends, ReadPathsAllocateNothingOnceConfigured) {
  // Arrange
  const hal::Recording rec = recording(25600.0, 25600, 14.3032);
  std::vector<hal::BundleScadaRow> rows{{0.0, 5.0, 8.0, std::nullopt, std::nullopt, std::nullopt},
                                        {0.5, 6.0, 8.2, std::nullopt, std::nullopt, std::nullopt}};
  hal::ReplayClock clock;
  hal::ReplayCmsStream cms(rec, clock);
  hal::ReplayKeyphasor kp(rec, clock);
  hal::ReplayScadaSource scada(rows);
  for (hal::Device* d : std::initializer_list<hal::Device*>{&cms, &kp, &scada}) {
    ASSERT_EQ(d->configure(), Status::kOk);
    ASSERT_EQ(d->activate(), Status::kOk);
  }
  hal::CmsBlock b;
  hal::KeyphasorEdge e;
  hal::ScadaData d;
  std::size_t blocks = 0;

  // Act: the whole second in 10 ms steps
  no_alloc::Scope scope;
  for (int k = 0; k < 100; ++k) {
    clock.advance(10ms);
    while (cms.read(b) == Status::kOk) ++blocks;
    while (kp.read(e) == Status::kOk) {
    }
    (void)scada.read(clock.now(), d);
  }

  // Assert: 914 blocks of 28 per channel, 2 channels
  EXPECT_EQ(scope.allocations(), 0u);
  EXPECT_EQ(blocks, 2u * (25600u / 28u));
}

}  // namespace
