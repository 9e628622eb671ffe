// Trends and events in SQLite: see trends_writer.hpp and docs/trends.md.
#include "trends/trends_writer.hpp"

#include <sqlite3.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace app::trends {
namespace {

constexpr std::array<int, 2> kPeriods{60, 600};  // [s] the two tiers
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kEventRepeat_s = 60.0;  // [s] one logged change per bit per this (others counted)

// The schema (docs/trends.md). auto_vacuum must precede the first table.
constexpr const char* kSchema = R"sql(
PRAGMA auto_vacuum = INCREMENTAL;
CREATE TABLE IF NOT EXISTS meta(key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS channels(
  id INTEGER PRIMARY KEY, key TEXT NOT NULL UNIQUE);
CREATE TABLE IF NOT EXISTS operating(
  period_s INTEGER NOT NULL, t_unix_s INTEGER NOT NULL, t_loop_s REAL NOT NULL,
  samples INTEGER NOT NULL,
  rotor_speed_rpm_mean REAL, rotor_speed_rpm_min REAL, rotor_speed_rpm_max REAL,
  rotor_torque_nm_mean REAL, rotor_torque_nm_min REAL, rotor_torque_nm_max REAL,
  wind_speed_mps_mean REAL, wind_speed_mps_min REAL, wind_speed_mps_max REAL,
  power_kw_mean REAL, power_kw_min REAL, power_kw_max REAL,
  hss_speed_rpm_mean REAL, scada_age_s_max REAL,
  torque_source INTEGER, status_any INTEGER NOT NULL, fault_any INTEGER NOT NULL,
  calibration_generation INTEGER, calibration_residual REAL,
  overruns INTEGER, cycle_time_us_max REAL, wakeup_latency_us_max REAL,
  PRIMARY KEY(period_s, t_unix_s)) WITHOUT ROWID;
CREATE TABLE IF NOT EXISTS indicators(
  period_s INTEGER NOT NULL, t_unix_s INTEGER NOT NULL, point INTEGER NOT NULL,
  accel_rms_10_2000_mps2 REAL, velocity_rms_10_1000_mmps REAL, accel_rms_01_10_mps2 REAL,
  rms_mps2_mean REAL, rms_mps2_max REAL, kurtosis_mean REAL, kurtosis_max REAL,
  zone_max INTEGER, f1 REAL, f2 REAL, f3 REAL,
  PRIMARY KEY(period_s, t_unix_s, point)) WITHOUT ROWID;
CREATE TABLE IF NOT EXISTS damage(
  period_s INTEGER NOT NULL, t_unix_s INTEGER NOT NULL, channel_id INTEGER NOT NULL,
  damage REAL, damage_increment REAL, rul_h REAL, rul_low_h REAL, load_mean REAL, load_max REAL,
  PRIMARY KEY(period_s, t_unix_s, channel_id)) WITHOUT ROWID;
CREATE TABLE IF NOT EXISTS calibrations(
  t_unix_s REAL NOT NULL, t_loop_s REAL NOT NULL, generation INTEGER NOT NULL, residual REAL,
  point1_f1 REAL, point1_f2 REAL, point1_f3 REAL, point2_f1 REAL, point2_f2 REAL, point2_f3 REAL);
CREATE TABLE IF NOT EXISTS events(
  id INTEGER PRIMARY KEY, t_unix_s REAL NOT NULL, t_loop_s REAL NOT NULL, kind TEXT NOT NULL,
  code INTEGER, value REAL, text TEXT);
CREATE INDEX IF NOT EXISTS events_by_time ON events(t_unix_s);
CREATE INDEX IF NOT EXISTS calibrations_by_time ON calibrations(t_unix_s);
)sql";

enum Stmt : std::size_t {
  kBegin,
  kCommit,
  kRollback,
  kOperating,
  kIndicator,
  kDamage,
  kCalibration,
  kEvent,
  kChannel,
  kChannelId,
  kStmtCount
};
constexpr std::array<const char*, kStmtCount> kSql{
    "BEGIN",
    "COMMIT",
    "ROLLBACK",
    "INSERT OR REPLACE INTO operating VALUES(?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?)",
    "INSERT OR REPLACE INTO indicators VALUES(?,?,?,?,?,?,?,?,?,?,?,?,?,?)",
    "INSERT OR REPLACE INTO damage VALUES(?,?,?,?,?,?,?,?,?)",
    "INSERT INTO calibrations VALUES(?,?,?,?,?,?,?,?,?,?)",
    "INSERT INTO events(t_unix_s, t_loop_s, kind, code, value, text) VALUES(?,?,?,?,?,?)",
    "INSERT OR IGNORE INTO channels(key) VALUES(?)",
    "SELECT id FROM channels WHERE key = ?",
};

struct Stat {
  double sum = 0.0, lo = std::numeric_limits<double>::infinity(),
         hi = -std::numeric_limits<double>::infinity();
  std::uint64_t n = 0;
  void add(double v) {
    if (!std::isfinite(v)) return;
    sum += v;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
    ++n;
  }
};

struct Last {
  double v = std::numeric_limits<double>::quiet_NaN();
  void add(double x) {
    if (std::isfinite(x)) v = x;
  }
};

const char* status_name(int bit) {
  static constexpr std::array<const char*, 8> kNames{"running",   "degraded",        "SCADA stale",
                                                     "CMS fault", "keyphasor fault", "calibrated",
                                                     "alarm",     "overrun"};
  return bit >= 0 && bit < 8 ? kNames[static_cast<std::size_t>(bit)] : "?";
}

}  // namespace

struct TrendsWriter::Aggregate {
  int period_s = 60;
  std::int64_t bucket = std::numeric_limits<std::int64_t>::min();  // none open
  double t_loop_start = 0.0;
  std::uint64_t samples = 0;
  Stat speed, torque, wind, power, hss, age;
  std::array<std::uint64_t, 6> source{};
  std::uint16_t status_any = 0, fault_any = 0;
  Last generation, residual;
  std::uint64_t overruns_first = 0, overruns_last = 0;
  Stat cycle, latency;
  struct Point {
    Last accel_hf, velocity, accel_lf;
    Stat rms, kurtosis;
    int zone_max = -1;
    Last f[3];
  };
  std::array<Point, loop::kSnapshotPoints> points{};
  struct Channel {
    Last damage, rul, rul_low;
    Stat load;
    double before =
        std::numeric_limits<double>::quiet_NaN();  // damage at the previous interval's end
  };
  std::vector<Channel> channels;

  void open(std::int64_t b, double t_loop) {
    std::vector<Channel> keep = std::move(channels);
    const int p = period_s;
    *this = Aggregate{};
    period_s = p;
    bucket = b;
    t_loop_start = t_loop;
    channels = std::move(keep);
    for (Channel& c : channels) {
      const double before = std::isfinite(c.damage.v) ? c.damage.v : c.before;
      c = Channel{};
      c.before = before;
    }
  }
};

std::unique_ptr<TrendsWriter> TrendsWriter::open(const TrendsSettings& settings,
                                                 std::string* error) {
  std::unique_ptr<TrendsWriter> w(new TrendsWriter(settings));
  const auto bad = [&](const std::string& what) -> std::unique_ptr<TrendsWriter> {
    if (error) {
      *error = "trends database " + settings.path + ": " + what;
      if (w->db_ != nullptr) *error += std::string(" (") + sqlite3_errmsg(w->db_) + ")";
    }
    return nullptr;
  };
  if (sqlite3_open_v2(settings.path.c_str(), &w->db_,
                      SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX,
                      nullptr) != SQLITE_OK)
    return bad("cannot open");
  sqlite3_busy_timeout(w->db_, 200);  // a reader's brief lock (checkpoint) is waited for
  // WAL: readers (sqlite3, the dashboard) never block the writer and a killed writer leaves
  // a consistent database; synchronous NORMAL: a power cut may lose the last transactions,
  // never the file's consistency.
  char* msg = nullptr;
  if (sqlite3_exec(w->db_, "PRAGMA journal_mode = WAL", nullptr, nullptr, &msg) != SQLITE_OK) {
    sqlite3_free(msg);
    return bad("cannot switch to WAL mode");
  }
  if (sqlite3_exec(w->db_, "PRAGMA synchronous = NORMAL", nullptr, nullptr, nullptr) != SQLITE_OK ||
      sqlite3_exec(w->db_, kSchema, nullptr, nullptr, nullptr) != SQLITE_OK)
    return bad("cannot create the schema");
  for (std::size_t i = 0; i < kStmtCount; ++i) {
    sqlite3_stmt* st = nullptr;
    if (sqlite3_prepare_v3(w->db_, kSql[i], -1, SQLITE_PREPARE_PERSISTENT, &st, nullptr) !=
        SQLITE_OK)
      return bad(std::string("cannot prepare ") + kSql[i]);
    w->stmts_[i] = st;
  }
  // meta: the schema version decides whether this build can write the file.
  sqlite3_stmt* q = nullptr;
  int existing = 0;
  if (sqlite3_prepare_v2(w->db_, "SELECT value FROM meta WHERE key = 'schema_version'", -1, &q,
                         nullptr) == SQLITE_OK &&
      sqlite3_step(q) == SQLITE_ROW)
    existing = sqlite3_column_int(q, 0);
  sqlite3_finalize(q);
  if (existing != 0 && existing != kTrendsSchemaVersion)
    return bad("schema version " + std::to_string(existing) + " (this build writes " +
               std::to_string(kTrendsSchemaVersion) + "): move the file aside");
  sqlite3_stmt* m = nullptr;
  bool meta_ok = sqlite3_prepare_v2(w->db_, "INSERT OR REPLACE INTO meta VALUES(?, ?)", -1, &m,
                                    nullptr) == SQLITE_OK;
  for (const auto& [key, value] :
       {std::pair<std::string, std::string>{"schema_version", std::to_string(kTrendsSchemaVersion)},
        {"snapshot_version", std::to_string(loop::kSnapshotVersion)},
        {"drivetrain", settings.drivetrain}}) {
    if (!meta_ok) break;
    sqlite3_bind_text(m, 1, key.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(m, 2, value.c_str(), -1, SQLITE_TRANSIENT);
    meta_ok = sqlite3_step(m) == SQLITE_DONE;
    sqlite3_reset(m);
  }
  sqlite3_finalize(m);
  if (!meta_ok) return bad("cannot write meta");
  // Channel ids, stable across restarts by key.
  for (const std::string& key : settings.channel_keys) {
    sqlite3_stmt* ins = w->stmts_[kChannel];
    sqlite3_bind_text(ins, 1, key.c_str(), -1, SQLITE_TRANSIENT);
    const int rc = sqlite3_step(ins);
    sqlite3_reset(ins);
    sqlite3_stmt* sel = w->stmts_[kChannelId];
    sqlite3_bind_text(sel, 1, key.c_str(), -1, SQLITE_TRANSIENT);
    const bool found = sqlite3_step(sel) == SQLITE_ROW;
    w->channel_id_.push_back(found ? sqlite3_column_int64(sel, 0) : -1);
    sqlite3_reset(sel);
    if (rc != SQLITE_DONE || !found) return bad("cannot register channel " + key);
  }
  w->set_max_size_bytes(settings.max_size_bytes);
  for (std::size_t t = 0; t < 2; ++t) {
    w->tier_[t] = std::make_unique<Aggregate>();
    w->tier_[t]->period_s = kPeriods[t];
    w->tier_[t]->channels.resize(settings.channel_keys.size());
  }
  return w;
}

TrendsWriter::TrendsWriter(const TrendsSettings& settings)
    : settings_(settings), stmts_(kStmtCount, nullptr), last_(std::make_unique<loop::Snapshot>()) {
  bit_event_t_.fill(-1e300);
}

TrendsWriter::~TrendsWriter() {
  for (sqlite3_stmt* s : stmts_) sqlite3_finalize(s);
  if (db_ != nullptr) sqlite3_close(db_);
}

void TrendsWriter::set_max_size_bytes(std::uint64_t bytes) {
  settings_.max_size_bytes = bytes;
  sqlite3_stmt* q = nullptr;
  std::int64_t page = 4096;
  if (sqlite3_prepare_v2(db_, "PRAGMA page_size", -1, &q, nullptr) == SQLITE_OK &&
      sqlite3_step(q) == SQLITE_ROW)
    page = sqlite3_column_int64(q, 0);
  sqlite3_finalize(q);
  // 0 pages would mean "no change" to SQLite: no cap is its maximum, 4294967294 pages.
  const std::uint64_t pages =
      bytes == 0 ? 4294967294ull
                 : std::max<std::uint64_t>(1, bytes / static_cast<std::uint64_t>(page));
  const std::string sql = "PRAGMA max_page_count = " + std::to_string(pages);
  (void)exec(sql.c_str(), "size limit");
}

void TrendsWriter::fail(const char* purpose) {
  ++stats_.errors;
  stats_.last_error = std::string(purpose) + ": " + sqlite3_errmsg(db_);
}

bool TrendsWriter::exec(const char* sql, const char* purpose) {
  if (sqlite3_exec(db_, sql, nullptr, nullptr, nullptr) == SQLITE_OK) return true;
  fail(purpose);
  return false;
}

namespace {
// Binds a value or NULL; steps and resets. False on an error.
struct Binder {
  sqlite3_stmt* s;
  int i = 1;
  Binder& i64(std::int64_t v) {
    sqlite3_bind_int64(s, i++, v);
    return *this;
  }
  Binder& real(double v) {
    if (std::isfinite(v)) {
      sqlite3_bind_double(s, i++, v);
    } else {
      sqlite3_bind_null(s, i++);
    }
    return *this;
  }
  Binder& text(const std::string& v) {
    sqlite3_bind_text(s, i++, v.c_str(), -1, SQLITE_TRANSIENT);
    return *this;
  }
  Binder& stat(const Stat& st) {
    real(st.n ? st.sum / static_cast<double>(st.n) : kNaN);
    real(st.n ? st.lo : kNaN);
    return real(st.n ? st.hi : kNaN);
  }
  bool step() {
    const int rc = sqlite3_step(s);
    sqlite3_reset(s);
    sqlite3_clear_bindings(s);
    return rc == SQLITE_DONE;
  }
};
double mean(const Stat& s) { return s.n ? s.sum / static_cast<double>(s.n) : kNaN; }
double hi(const Stat& s) { return s.n ? s.hi : kNaN; }
}  // namespace

void TrendsWriter::close_interval(Aggregate& a) {
  if (a.bucket == std::numeric_limits<std::int64_t>::min() || a.samples == 0) return;
  const std::int64_t t_unix = a.bucket * a.period_s;
  bool ok = sqlite3_exec(db_, "BEGIN", nullptr, nullptr, nullptr) == SQLITE_OK;
  std::uint64_t rows = 0;
  if (ok) {
    int source = 0;
    for (std::size_t k = 1; k < a.source.size(); ++k)
      if (a.source[k] > a.source[static_cast<std::size_t>(source)]) source = static_cast<int>(k);
    Binder b{stmts_[kOperating]};
    b.i64(a.period_s).i64(t_unix).real(a.t_loop_start).i64(static_cast<std::int64_t>(a.samples));
    b.stat(a.speed).stat(a.torque).stat(a.wind).stat(a.power).real(mean(a.hss)).real(hi(a.age));
    b.i64(source).i64(a.status_any).i64(a.fault_any).real(a.generation.v).real(a.residual.v);
    b.i64(static_cast<std::int64_t>(a.overruns_last - a.overruns_first))
        .real(hi(a.cycle))
        .real(hi(a.latency));
    ok = b.step();
    ++rows;
  }
  for (std::size_t p = 0; ok && p < a.points.size(); ++p) {
    const Aggregate::Point& pt = a.points[p];
    Binder b{stmts_[kIndicator]};
    b.i64(a.period_s).i64(t_unix).i64(static_cast<std::int64_t>(p) + 1);
    b.real(pt.accel_hf.v).real(pt.velocity.v).real(pt.accel_lf.v);
    b.real(mean(pt.rms)).real(hi(pt.rms)).real(mean(pt.kurtosis)).real(hi(pt.kurtosis));
    if (pt.zone_max >= 0) {
      b.i64(pt.zone_max);
    } else {
      b.real(kNaN);
    }
    b.real(pt.f[0].v).real(pt.f[1].v).real(pt.f[2].v);
    ok = b.step();
    ++rows;
  }
  for (std::size_t c = 0; ok && c < a.channels.size(); ++c) {
    const Aggregate::Channel& ch = a.channels[c];
    if (!std::isfinite(ch.damage.v)) continue;
    Binder b{stmts_[kDamage]};
    b.i64(a.period_s).i64(t_unix).i64(channel_id_[c]).real(ch.damage.v);
    b.real(std::isfinite(ch.before) ? ch.damage.v - ch.before : kNaN);
    b.real(ch.rul.v).real(ch.rul_low.v).real(mean(ch.load)).real(hi(ch.load));
    ok = b.step();
    ++rows;
  }
  if (ok) ok = sqlite3_exec(db_, "COMMIT", nullptr, nullptr, nullptr) == SQLITE_OK;
  if (!ok) {
    fail("interval rows");
    ++stats_.lost_intervals;
    if (sqlite3_get_autocommit(db_) == 0)
      (void)sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    return;
  }
  stats_.rows += rows;
  ++stats_.intervals;
  if (a.period_s == kPeriods[1]) prune(static_cast<double>(t_unix + a.period_s));
}

void TrendsWriter::prune(double now_unix_s) {
  const auto del = [&](const char* table, const char* where, double cutoff) {
    const std::string sql = std::string("DELETE FROM ") + table + " WHERE " + where +
                            std::to_string(static_cast<std::int64_t>(std::floor(cutoff)));
    (void)exec(sql.c_str(), "retention");
  };
  del("operating", "period_s = 60 AND t_unix_s < ", now_unix_s - settings_.retention_1min_s);
  del("indicators", "period_s = 60 AND t_unix_s < ", now_unix_s - settings_.retention_1min_s);
  del("damage", "period_s = 60 AND t_unix_s < ", now_unix_s - settings_.retention_1min_s);
  del("operating", "period_s = 600 AND t_unix_s < ", now_unix_s - settings_.retention_10min_s);
  del("indicators", "period_s = 600 AND t_unix_s < ", now_unix_s - settings_.retention_10min_s);
  del("damage", "period_s = 600 AND t_unix_s < ", now_unix_s - settings_.retention_10min_s);
  del("events", "t_unix_s < ", now_unix_s - settings_.retention_events_s);
  del("calibrations", "t_unix_s < ", now_unix_s - settings_.retention_events_s);
  (void)exec("PRAGMA incremental_vacuum(256)", "vacuum");
}

void TrendsWriter::event(std::int64_t stamp_ns, const std::string& kind, int code, double value,
                         const std::string& text) {
  const double t_loop = 1e-9 * static_cast<double>(stamp_ns);
  Binder b{stmts_[kEvent]};
  b.real(settings_.origin_unix_s + t_loop).real(t_loop).text(kind).i64(code).real(value).text(text);
  if (b.step()) {
    ++stats_.events;
    ++stats_.rows;
  } else {
    fail("event");
  }
}

void TrendsWriter::changes(const loop::Snapshot& p, const loop::Snapshot& s) {
  const double t = 1e-9 * static_cast<double>(s.stamp_ns);
  const auto bits = [&](std::uint16_t before, std::uint16_t after, const char* kind, int offset) {
    const std::uint16_t changed = before ^ after;
    for (int bit = 0; bit < 16; ++bit) {
      if ((changed & (1u << bit)) == 0) continue;
      double& last = bit_event_t_[static_cast<std::size_t>(offset + bit)];
      if (t - last < kEventRepeat_s) {
        ++stats_.events_suppressed;  // flickering: the interval rows show it
        continue;
      }
      last = t;
      const bool set = (after & (1u << bit)) != 0;
      std::string text = std::string(set ? "set: " : "cleared: ");
      text += offset == 0 ? status_name(bit) : ("fault bit " + std::to_string(bit));
      event(s.stamp_ns, kind, bit, set ? 1.0 : 0.0, text);
    }
  };
  bits(p.status_word, s.status_word, "status", 0);
  bits(p.fault_word, s.fault_word, "fault", 16);
  if (p.torque_source != s.torque_source)
    event(s.stamp_ns, "inputs", static_cast<int>(s.torque_source),
          static_cast<double>(s.rotor_torque_nm),
          std::string("ROM inputs from ") + loop::to_string(s.torque_source));
  for (std::size_t i = 0; i < loop::kSnapshotPoints; ++i) {
    if (p.points[i].zone == s.points[i].zone) continue;
    const bool alarm =
        s.points[i].zone == loop::VibrationZone::kC || s.points[i].zone == loop::VibrationZone::kD;
    event(s.stamp_ns, alarm ? "alarm" : "zone", static_cast<int>(i) + 1,
          static_cast<double>(s.points[i].zone),
          "point" + std::to_string(i + 1) + ": ISO 10816-21 zone " +
              loop::to_string(s.points[i].zone));
  }
  if (s.calibration_generation != p.calibration_generation) {
    Binder b{stmts_[kCalibration]};
    b.real(settings_.origin_unix_s + t)
        .real(t)
        .i64(s.calibration_generation)
        .real(static_cast<double>(s.calibration_residual));
    for (std::size_t i = 0; i < loop::kSnapshotPoints; ++i)
      for (std::size_t k = 0; k < 3; ++k) b.real(static_cast<double>(s.fit[i][k]));
    if (b.step()) {
      ++stats_.rows;
    } else {
      fail("calibration");
    }
    event(s.stamp_ns, "calibration", s.calibration_generation,
          static_cast<double>(s.calibration_residual),
          "calibrated model adopted (generation " + std::to_string(s.calibration_generation) + ")");
  }
}

void TrendsWriter::add(const loop::Snapshot& s) {
  ++stats_.snapshots;
  const double t_loop = 1e-9 * static_cast<double>(s.stamp_ns);
  const double t_unix = settings_.origin_unix_s + t_loop;
  if (have_last_) {
    if (s.stamp_ns < last_->stamp_ns) {
      ++stats_.out_of_order;
      return;
    }
    changes(*last_, s);
  } else {
    event(s.stamp_ns, "start", s.status_word, t_loop, "trends started");
  }
  for (auto& tier : tier_) {
    Aggregate& a = *tier;
    const auto b = static_cast<std::int64_t>(std::floor(t_unix / a.period_s));
    if (b != a.bucket) {
      close_interval(a);
      a.open(b, t_loop);
    }
    ++a.samples;
    a.speed.add(static_cast<double>(s.rotor_speed_rpm));
    a.torque.add(static_cast<double>(s.rotor_torque_nm));
    a.wind.add(static_cast<double>(s.wind_speed_mps));
    a.power.add(static_cast<double>(s.power_kw));
    a.hss.add(static_cast<double>(s.hss_speed_rpm));
    a.age.add(static_cast<double>(s.scada_age_s));
    const auto src = static_cast<std::size_t>(s.torque_source);
    if (src < a.source.size()) ++a.source[src];
    a.status_any |= s.status_word;
    a.fault_any |= s.fault_word;
    a.generation.add(s.calibration_generation);
    a.residual.add(static_cast<double>(s.calibration_residual));
    if (a.samples == 1) a.overruns_first = s.counters.overruns;
    a.overruns_last = s.counters.overruns;
    a.cycle.add(static_cast<double>(s.counters.cycle_time_max_us));
    a.latency.add(static_cast<double>(s.counters.wakeup_latency_max_us));
    for (std::size_t i = 0; i < loop::kSnapshotPoints; ++i) {
      const loop::PointSnapshot& ps = s.points[i];
      Aggregate::Point& pt = a.points[i];
      pt.accel_hf.add(static_cast<double>(ps.accel_rms_10_2000_mps2));
      pt.velocity.add(static_cast<double>(ps.velocity_rms_10_1000_mmps));
      pt.accel_lf.add(static_cast<double>(ps.accel_rms_01_10_mps2));
      pt.rms.add(static_cast<double>(ps.rms_mps2));
      pt.kurtosis.add(static_cast<double>(ps.kurtosis));
      if (ps.zone != loop::VibrationZone::kUnknown)
        pt.zone_max = std::max(pt.zone_max, static_cast<int>(ps.zone));
      for (std::size_t k = 0; k < 3; ++k) pt.f[k].add(static_cast<double>(s.fit[i][k]));
    }
    const std::size_t n = std::min<std::size_t>(s.channel_count, a.channels.size());
    for (std::size_t c = 0; c < n; ++c) {
      const results::ChannelResult& r = s.channels[c];
      Aggregate::Channel& ch = a.channels[c];
      if (!std::isfinite(ch.before) && !std::isfinite(ch.damage.v))
        ch.before = static_cast<double>(r.damage);  // first ever
      ch.damage.add(static_cast<double>(r.damage));
      ch.rul.add(static_cast<double>(r.rul_h));
      ch.rul_low.add(static_cast<double>(r.rul_low_h));
      ch.load.add(static_cast<double>(r.load));
    }
  }
  *last_ = s;
  have_last_ = true;
}

void TrendsWriter::flush() {
  for (auto& tier : tier_) {
    close_interval(*tier);
    tier->bucket = std::numeric_limits<std::int64_t>::min();
  }
  (void)exec("PRAGMA wal_checkpoint(TRUNCATE)", "checkpoint");
}

}  // namespace app::trends
