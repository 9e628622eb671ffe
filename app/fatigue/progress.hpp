#pragma once
// When a command draws a progress bar: only on a terminal, never into a pipe, a file or a
// CI log (where the carriage returns would pile up as one long line).
//
// ProgressLine: one line redrawn in place for a command that runs more than a few seconds
// (the dynamics load spectrum, the per-row dynamics, ...):
//
//   load spectrum (dynamics): 37/96 points  38.5 %  41 s, ~66 s left
//
// at most four redraws a second; finish() ends the line. Disabled, it prints nothing.
//
// Thread context: non-real-time command code (reads the steady clock).

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <string>
#include <thread>

namespace app::fatigue {

/// True when `fd` is a terminal and the user did not pass --no-progress.
bool show_progress(bool no_progress, int fd);

class ProgressLine {
 public:
  /// `unit` names what is counted ("points", "rows"); `total` ≤ 0: unknown, no % or ETA.
  ProgressLine(bool enabled, std::string label, std::string unit, double total,
               std::FILE* out = stderr);
  ~ProgressLine() { finish(); }
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  /// `done` items so far; redraws when the last redraw is ≥ 0.25 s old (or on the first).
  void update(double done);
  /// Draws the final count and ends the line (once; no-op when nothing was drawn).
  void finish();

 private:
  void draw(double done, double elapsed_s);

  bool enabled_;
  std::string label_;
  std::string unit_;
  double total_;
  std::FILE* out_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_{};
  double done_ = 0.0;
  bool drawn_ = false;
  bool finished_ = false;
};

/// For a call that cannot report its own progress (a model run): while it lives, a thread
/// redraws "<label>: 12 s" every half second on the line; the destructor ends the line.
/// Disabled, no thread is started and nothing is printed.
class ElapsedTicker {
 public:
  ElapsedTicker(bool enabled, std::string label, std::FILE* out = stderr);
  ~ElapsedTicker();
  ElapsedTicker(const ElapsedTicker&) = delete;
  ElapsedTicker& operator=(const ElapsedTicker&) = delete;

 private:
  ProgressLine line_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace app::fatigue
