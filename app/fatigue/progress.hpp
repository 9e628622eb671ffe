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
#include <cstdio>
#include <string>

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

}  // namespace app::fatigue
