#pragma once
// Trends and events of `drivetwin run` in an embedded SQLite database (WAL mode), written by
// a non-real-time thread from the loop's results snapshots (app/loop/snapshot.hpp): 1-minute
// and 10-minute aggregates of the operating data, the condition indicators and ISO 10816-21
// values per measurement point, damage and RUL per damage channel; every calibration the
// loop adopts; status and fault changes, zone changes and alarms as events. The schema, the
// retention and the size bound are in docs/trends.md; `sqlite3 FILE` reads it, and so can a
// dashboard while the twin writes (WAL: readers never block the writer).
//
// Aggregation: an interval is [k·P, (k+1)·P) of wall-clock time (UTC seconds = origin + loop
// time), P = 60 s and 600 s, so rows line up with the clock's minutes; a row is written when
// the first snapshot of the next interval arrives (one transaction per closed interval), and
// flush() writes the open ones at shutdown (their `samples` say how complete they are).
// Values the loop does not have (NaN) are left out of means and extremes; a column with no
// value in an interval is NULL.
//
// Failure: every SQLite error (disk full, read-only, I/O) is counted and kept as the last
// error; the rows of that interval are lost, nothing else: the writer keeps going and the next
// interval is written when the database accepts it again. It never throws after open().
//
// Retention: rows older than the tier's retention (by their interval start) are deleted when
// a 10-minute interval closes; freed pages are reused (and returned by incremental vacuum), so
// the file stays bounded (docs/trends.md).
//
// Thread context: one non-RT thread (the trends thread) calls add()/flush(); construction and
// destruction on any thread. Allocates.

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "loop/snapshot.hpp"

struct sqlite3;
struct sqlite3_stmt;

namespace app::trends {

inline constexpr int kTrendsSchemaVersion = 1;

struct TrendsSettings {
  std::string path;            // the database file (created if missing)
  double origin_unix_s = 0.0;  // [s] UTC time of loop time 0
  std::string drivetrain;      // description name (meta)
  std::vector<std::string>
      channel_keys;  // damage channels, snapshot order ("component/detail/mode")
  double retention_1min_s = 7 * 86400.0;      // [s]
  double retention_10min_s = 365 * 86400.0;   // [s]
  double retention_events_s = 730 * 86400.0;  // [s]
  /// Hard cap on the file [bytes] (0: none): past it SQLite refuses to grow the file and the
  /// writer loses intervals (counted) until retention frees pages — a safety net under the
  /// retention's bound, for a state partition shared with the persisted state.
  std::uint64_t max_size_bytes = 512ull << 20;
};

struct TrendsStats {
  std::uint64_t snapshots = 0;          // [-] added
  std::uint64_t rows = 0;               // [-] rows written (all tables)
  std::uint64_t intervals = 0;          // [-] intervals written (both tiers)
  std::uint64_t events = 0;             // [-] events written
  std::uint64_t events_suppressed = 0;  // [-] a bit's changes within a minute of its last event
  std::uint64_t errors = 0;             // [-] failed statements / transactions
  std::uint64_t lost_intervals = 0;     // [-] intervals whose rows were lost to an error
  std::uint64_t out_of_order = 0;       // [-] snapshots older than the open interval (ignored)
  std::string last_error;               // what SQLite said, with the statement's purpose
};

class TrendsWriter {
 public:
  /// Opens (creating) the database: WAL, schema, the channel table. nullptr with `error`
  /// naming the file and what failed (e.g. a read-only or missing directory).
  static std::unique_ptr<TrendsWriter> open(const TrendsSettings& settings, std::string* error);
  ~TrendsWriter();
  TrendsWriter(const TrendsWriter&) = delete;
  TrendsWriter& operator=(const TrendsWriter&) = delete;

  /// One snapshot (in loop-time order).
  void add(const loop::Snapshot& s);
  /// Writes the open intervals (shutdown).
  void flush();
  /// Records an event the snapshots cannot show (e.g. "persistence: save failed: …").
  void event(std::int64_t stamp_ns, const std::string& kind, int code, double value,
             const std::string& text);
  /// Changes the hard cap on the file (e.g. after the operator freed space) [bytes, 0: none].
  void set_max_size_bytes(std::uint64_t bytes);
  const TrendsStats& stats() const { return stats_; }
  const TrendsSettings& settings() const { return settings_; }

  struct Aggregate;  // one tier's open interval (trends_writer.cpp)

 private:
  explicit TrendsWriter(const TrendsSettings& settings);
  bool exec(const char* sql, const char* purpose);
  void close_interval(Aggregate& a);
  void changes(const loop::Snapshot& prev, const loop::Snapshot& s);
  void prune(double now_unix_s);
  void fail(const char* purpose);

  TrendsSettings settings_;
  sqlite3* db_ = nullptr;
  std::vector<sqlite3_stmt*> stmts_;
  std::unique_ptr<Aggregate> tier_[2];
  std::unique_ptr<loop::Snapshot> last_;
  bool have_last_ = false;
  std::vector<std::int64_t> channel_id_;
  std::array<double, 32>
      bit_event_t_;  // [s] loop time of each status (0–15) / fault (16–31) bit's last event
  TrendsStats stats_;
};

}  // namespace app::trends
