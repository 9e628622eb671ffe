// The trends database (app/trends/trends_writer.hpp): 1- and 10-minute rows with the means,
// extremes and damage increments of the snapshots they aggregate (checked against the
// closed forms of the synthetic inputs), events for status/fault/zone/calibration changes,
// retention bounding the rows, a size cap that loses intervals but never the database, and a
// file `PRAGMA integrity_check` accepts, readable by a second connection while written.
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>

#include "loop/snapshot.hpp"
#include "trends/trends_writer.hpp"

namespace {

namespace fs = std::filesystem;
using app::loop::Snapshot;
using app::trends::TrendsSettings;
using app::trends::TrendsWriter;

constexpr double kOrigin = 1575504000.0;  // 2019-12-05 00:00:00 UTC

fs::path fresh_dir(const std::string& name) {
  const fs::path d =
      fs::path(testing::TempDir()) / ("trends-" + name + "-" + std::to_string(getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

TrendsSettings settings_in(const fs::path& dir) {
  TrendsSettings s;
  s.path = (dir / "trends.db").string();
  s.origin_unix_s = kOrigin;
  s.drivetrain = "paper-2mw";
  s.channel_keys = {"sun/contact", "b1/bearing"};
  return s;
}

// Snapshot at loop time t [s]: speed 10 + t/3600 rpm, torque 5e5 N·m, channel 0's damage
// 1e-6·t, channel 1's 2e-6·t.
Snapshot snap(double t) {
  Snapshot s;
  s.stamp_ns = static_cast<std::int64_t>(std::llround(t * 1e9));
  s.rotor_speed_rpm = static_cast<float>(10.0 + t / 3600.0);
  s.rotor_torque_nm = 5e5f;
  s.status_word = 1;
  s.channel_count = 2;
  s.channels[0].damage = static_cast<float>(1e-6 * t);
  s.channels[1].damage = static_cast<float>(2e-6 * t);
  s.channels[0].load = static_cast<float>(100.0 + std::fmod(t, 60.0));
  return s;
}

struct Db {
  sqlite3* db = nullptr;
  explicit Db(const std::string& path) {
    EXPECT_EQ(sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  }
  ~Db() { sqlite3_close(db); }
  double scalar(const std::string& sql) const {
    sqlite3_stmt* s = nullptr;
    EXPECT_EQ(sqlite3_prepare_v2(db, sql.c_str(), -1, &s, nullptr), SQLITE_OK) << sql;
    double v = std::numeric_limits<double>::quiet_NaN();
    if (s && sqlite3_step(s) == SQLITE_ROW && sqlite3_column_type(s, 0) != SQLITE_NULL)
      v = sqlite3_column_double(s, 0);
    sqlite3_finalize(s);
    return v;
  }
  std::string text(const std::string& sql) const {
    sqlite3_stmt* s = nullptr;
    EXPECT_EQ(sqlite3_prepare_v2(db, sql.c_str(), -1, &s, nullptr), SQLITE_OK) << sql;
    std::string v;
    if (s && sqlite3_step(s) == SQLITE_ROW && sqlite3_column_text(s, 0))
      v = reinterpret_cast<const char*>(sqlite3_column_text(s, 0));
    sqlite3_finalize(s);
    return v;
  }
};

TEST(TrendsWriter, TwoHoursOfSnapshotsGiveMinuteAndTenMinuteRowsWithTheirMeansAndIncrements) {
  // Arrange
  const fs::path dir = fresh_dir("two-hours");
  std::string error;
  auto w = TrendsWriter::open(settings_in(dir), &error);
  ASSERT_TRUE(w) << error;
  // Act: 10 snapshots per second for 2 h.
  for (int k = 0; k < 72000; ++k) w->add(snap(0.1 * k));
  w->flush();
  // Assert
  const Db db(settings_in(dir).path);
  EXPECT_EQ(db.scalar("SELECT count(*) FROM operating WHERE period_s = 60"), 120);
  EXPECT_EQ(db.scalar("SELECT count(*) FROM operating WHERE period_s = 600"), 12);
  EXPECT_EQ(db.scalar("SELECT min(t_unix_s) FROM operating"), kOrigin);
  EXPECT_EQ(db.scalar("SELECT samples FROM operating WHERE period_s = 60 AND t_unix_s = " +
                      std::to_string(static_cast<long>(kOrigin) + 600)),
            600);
  // Minute k's snapshots are at 60k + 0.1j, j < 600: mean speed 10 + (60k + 29.95)/3600.
  for (int k : {0, 17, 119}) {
    const double mean =
        db.scalar("SELECT rotor_speed_rpm_mean FROM operating WHERE period_s = 60 AND t_unix_s = " +
                  std::to_string(static_cast<long>(kOrigin) + 60 * k));
    EXPECT_NEAR(mean, 10.0 + (60.0 * k + 29.95) / 3600.0, 1e-5) << k;
  }
  EXPECT_NEAR(db.scalar("SELECT rotor_speed_rpm_max FROM operating WHERE period_s = 600 ORDER BY "
                        "t_unix_s DESC LIMIT 1"),
              10.0 + 7199.9 / 3600.0, 1e-5);
  // Damage increments add up to the damage accumulated since the first snapshot; a 10-minute
  // interval after the first is 600 s × the rate.
  EXPECT_NEAR(
      db.scalar("SELECT sum(damage_increment) FROM damage WHERE period_s = 600 AND channel_id = "
                "(SELECT id FROM channels WHERE key = 'b1/bearing')"),
      2e-6 * 7199.9, 1e-9);
  EXPECT_NEAR(db.scalar("SELECT damage_increment FROM damage WHERE period_s = 600 AND t_unix_s = " +
                        std::to_string(static_cast<long>(kOrigin) + 1200) + " AND channel_id = 1"),
              1e-6 * 600.0, 1e-9);
  EXPECT_NEAR(
      db.scalar("SELECT load_max FROM damage WHERE period_s = 60 AND channel_id = 1 LIMIT 1"),
      159.9, 1e-3);
  EXPECT_EQ(db.text("SELECT value FROM meta WHERE key = 'drivetrain'"), "paper-2mw");
  EXPECT_EQ(db.text("PRAGMA journal_mode"), "wal");
  EXPECT_EQ(db.text("PRAGMA integrity_check"), "ok");
  EXPECT_EQ(w->stats().errors, 0u);
}

TEST(TrendsWriter, StatusFaultZoneAndCalibrationChangesBecomeEventsAndFlickerIsCounted) {
  const fs::path dir = fresh_dir("events");
  std::string error;
  auto w = TrendsWriter::open(settings_in(dir), &error);
  ASSERT_TRUE(w) << error;
  for (int k = 0; k < 6000; ++k) {  // 600 s
    const double t = 0.1 * k;
    Snapshot s = snap(t);
    if (t >= 100.0 && t < 300.0) s.status_word |= 1u << 2;           // SCADA stale for 200 s
    if (t >= 400.0 && t < 430.0 && k % 2) s.fault_word |= 1u << 11;  // flickering
    if (t >= 200.0) s.points[0].zone = app::loop::VibrationZone::kD;
    if (t >= 500.0) {
      s.calibration_generation = 1;
      s.calibration_residual = 0.8f;
    }
    w->add(s);
  }
  w->flush();
  const Db db(settings_in(dir).path);
  EXPECT_EQ(db.scalar("SELECT count(*) FROM events WHERE kind = 'status' AND code = 2"), 2);
  EXPECT_EQ(db.scalar("SELECT t_loop_s FROM events WHERE kind = 'status' AND value = 0"), 300.0);
  EXPECT_EQ(db.scalar("SELECT count(*) FROM events WHERE kind = 'fault' AND code = 11"), 1);
  EXPECT_GT(w->stats().events_suppressed, 100u);
  EXPECT_EQ(db.scalar("SELECT count(*) FROM events WHERE kind = 'alarm' AND code = 1"), 1);
  EXPECT_EQ(db.scalar("SELECT generation FROM calibrations"), 1);
  EXPECT_NEAR(db.scalar("SELECT residual FROM calibrations"), 0.8, 1e-6);
  EXPECT_EQ(db.scalar("SELECT status_any & 4 FROM operating WHERE period_s = 600"), 4);
  EXPECT_EQ(db.scalar("SELECT zone_max FROM indicators WHERE period_s = 600 AND point = 1"), 3);
}

TEST(TrendsWriter, RetentionKeepsOnlyTheConfiguredHistoryOfEachTier) {
  const fs::path dir = fresh_dir("retention");
  TrendsSettings st = settings_in(dir);
  st.retention_1min_s = 3600.0;
  st.retention_10min_s = 3 * 3600.0;
  std::string error;
  auto w = TrendsWriter::open(st, &error);
  ASSERT_TRUE(w) << error;
  for (int k = 0; k < 6 * 3600; ++k) w->add(snap(k));  // 6 h, one per second
  w->flush();
  const Db db(st.path);
  // Pruned when a 10-minute interval closes: at most the retention + one 10-minute interval.
  EXPECT_LE(db.scalar("SELECT count(*) FROM operating WHERE period_s = 60"), 70);
  EXPECT_GE(db.scalar("SELECT count(*) FROM operating WHERE period_s = 60"), 60);
  EXPECT_LE(db.scalar("SELECT count(*) FROM operating WHERE period_s = 600"), 19);
  EXPECT_GE(db.scalar("SELECT min(t_unix_s) FROM operating WHERE period_s = 600"),
            kOrigin + 3 * 3600 - 600);
  EXPECT_EQ(db.text("PRAGMA integrity_check"), "ok");
}

TEST(TrendsWriter, ASizeCapLosesIntervalsNotTheDatabaseAndWritingResumesWhenRaised) {
  const fs::path dir = fresh_dir("full");
  TrendsSettings st = settings_in(dir);
  st.max_size_bytes = 64 * 1024;  // 16 pages
  std::string error;
  auto w = TrendsWriter::open(st, &error);
  ASSERT_TRUE(w) << error;
  int k = 0;
  for (; k < 3 * 86400 && w->stats().lost_intervals == 0; k += 2) w->add(snap(k));
  ASSERT_GT(w->stats().lost_intervals, 0u) << "the cap never bit";
  EXPECT_NE(w->stats().last_error.find("full"), std::string::npos) << w->stats().last_error;
  const std::uint64_t written = w->stats().intervals;
  w->set_max_size_bytes(0);
  for (int j = 0; j < 1800; ++j, k += 2) w->add(snap(k));
  w->flush();
  EXPECT_GT(w->stats().intervals, written);
  const Db db(st.path);
  EXPECT_EQ(db.text("PRAGMA integrity_check"), "ok");
}

TEST(TrendsWriter, AnUnwritableFolderIsRefusedNamingTheFile) {
  TrendsSettings st = settings_in(fresh_dir("readonly"));
  st.path =
      (fs::path(testing::TempDir()) / "no-such-folder-for-trends" / "x" / "trends.db").string();
  std::string error;
  EXPECT_FALSE(TrendsWriter::open(st, &error));
  EXPECT_NE(error.find(st.path), std::string::npos) << error;
}

TEST(TrendsWriter, AReaderSeesCommittedRowsWhileTheWriterGoesOn) {
  const fs::path dir = fresh_dir("reader");
  std::string error;
  auto w = TrendsWriter::open(settings_in(dir), &error);
  ASSERT_TRUE(w) << error;
  for (int k = 0; k < 1300; ++k) w->add(snap(k));  // 21 minutes: 21 closed minute rows
  const Db db(settings_in(dir).path);
  EXPECT_EQ(db.scalar("SELECT count(*) FROM operating WHERE period_s = 60"), 21);
  for (int k = 1300; k < 1500; ++k) w->add(snap(k));
  EXPECT_EQ(db.scalar("SELECT count(*) FROM operating WHERE period_s = 60"), 24);
}

}  // namespace
