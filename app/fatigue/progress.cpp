#include "fatigue/progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <utility>

namespace app::fatigue {

bool show_progress(bool no_progress, int fd) { return !no_progress && isatty(fd) == 1; }

ProgressLine::ProgressLine(bool enabled, std::string label, std::string unit, double total,
                           std::FILE* out)
    : enabled_(enabled),
      label_(std::move(label)),
      unit_(std::move(unit)),
      total_(total),
      out_(out),
      start_(std::chrono::steady_clock::now()) {}

void ProgressLine::update(double done) {
  done_ = done;
  if (!enabled_ || finished_) return;
  const auto now = std::chrono::steady_clock::now();
  if (drawn_ && now - last_ < std::chrono::milliseconds(250)) return;
  last_ = now;
  draw(done, std::chrono::duration<double>(now - start_).count());
}

void ProgressLine::finish() {
  if (!enabled_ || finished_ || !drawn_) {
    finished_ = true;
    return;
  }
  draw(done_, std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count());
  std::fputc('\n', out_);
  std::fflush(out_);
  finished_ = true;
}

void ProgressLine::draw(double done, double elapsed_s) {
  drawn_ = true;
  if (total_ > 0.0) {
    const double f = std::clamp(done / total_, 0.0, 1.0);
    const double left = f > 0.0 ? elapsed_s * (1.0 - f) / f : 0.0;
    std::fprintf(out_, "\r%s: %.0f/%.0f %s  %5.1f %%  %.0f s", label_.c_str(), done, total_,
                 unit_.c_str(), 100.0 * f, elapsed_s);
    if (f > 0.0 && f < 1.0) std::fprintf(out_, ", ~%.0f s left", left);
    std::fputs("   ", out_);   // wipes the tail of a longer previous line
  } else if (unit_.empty()) {  // nothing counted: the time it has taken so far
    std::fprintf(out_, "\r%s: %.0f s   ", label_.c_str(), elapsed_s);
  } else {
    std::fprintf(out_, "\r%s: %.0f %s  %.0f s   ", label_.c_str(), done, unit_.c_str(), elapsed_s);
  }
  std::fflush(out_);
}

ElapsedTicker::ElapsedTicker(bool enabled, std::string label, std::FILE* out)
    : line_(enabled, std::move(label), "", 0.0, out) {
  if (!enabled) return;
  thread_ = std::thread([this] {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!wake_.wait_for(lock, std::chrono::milliseconds(500), [this] { return stop_; }))
      line_.update(0.0);
  });
}

ElapsedTicker::~ElapsedTicker() {
  if (thread_.joinable()) {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_one();
    thread_.join();
  }
  line_.finish();
}

}  // namespace app::fatigue
