// The pieces of `drivetwin damage` that need no command registry: --per-day's distribution
// of daily damage, and the progress bar only on a terminal.
#include <fcntl.h>
#include <stdlib.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "fatigue/damage_history.hpp"
#include "fatigue/progress.hpp"

namespace {

TEST(DayDistribution, QuartilesMedianAndNearestDaysFollowTheHandCalculation) {
  // Arrange: five full days with damage 5, 1, 4, 2, 3 (·1e-6) and daily mean wind 9, 5, 7, 6.5, 8
  // m/s, and one partial day. Sorted: 1 2 3 4 5 → type 7 quantiles at ranks 1, 2, 3: Q1 2, median
  // 3, Q3 4.
  std::vector<app::fatigue::DayRecord> days;
  const double damage[] = {5e-6, 1e-6, 4e-6, 2e-6, 3e-6};
  const double wind[] = {9.0, 5.0, 7.0, 6.5, 8.0};
  for (int i = 0; i < 5; ++i) {
    app::fatigue::DayRecord d;
    d.day = i;
    d.covered_s = 86400.0;
    d.wind_sum_mps = wind[i] * 144;
    d.wind_rows = 144;
    d.damage = {damage[i]};
    days.push_back(d);
  }
  app::fatigue::DayRecord partial;
  partial.covered_s = 600.0;
  partial.damage = {1.0};
  days.push_back(partial);
  // Act
  const auto dist = app::fatigue::day_distribution(days, 0, 86400.0, 6.75, 2);
  // Assert: |wind − 6.75| = 2.25, 1.75, 0.25, 0.25, 1.25 → days 2 and 3 (tie kept in order).
  EXPECT_EQ(dist.full_days, 5u);
  EXPECT_EQ(dist.partial_days, 1u);
  EXPECT_EQ(dist.all.count, 5u);
  EXPECT_DOUBLE_EQ(dist.all.min, 1e-6);
  EXPECT_DOUBLE_EQ(dist.all.q1, 2e-6);
  EXPECT_DOUBLE_EQ(dist.all.median, 3e-6);
  EXPECT_DOUBLE_EQ(dist.all.q3, 4e-6);
  EXPECT_DOUBLE_EQ(dist.all.max, 5e-6);
  EXPECT_DOUBLE_EQ(dist.all.mean, 3e-6);
  ASSERT_EQ(dist.nearest.size(), 2u);
  EXPECT_EQ(dist.nearest[0], 2u);
  EXPECT_EQ(dist.nearest[1], 3u);
  // Default band ±0.1 m/s around 6.75: no day (the nearest are 0.25 away).
  EXPECT_EQ(dist.band.count, 0u);

  // Band ±0.3 m/s: days 2 (7.0 m/s, 4e-6) and 3 (6.5 m/s, 2e-6) → median 3e-6 (rank 0.5),
  // Q1 2.5e-6, Q3 3.5e-6; the partial day is never counted.
  const auto banded = app::fatigue::day_distribution(days, 0, 86400.0, 6.75, 2, 0.3);
  EXPECT_EQ(banded.band.count, 2u);
  EXPECT_DOUBLE_EQ(banded.band.median, 3e-6);
  EXPECT_DOUBLE_EQ(banded.band.q1, 2.5e-6);
  EXPECT_DOUBLE_EQ(banded.band.q3, 3.5e-6);
  EXPECT_DOUBLE_EQ(banded.band.min, 2e-6);
  EXPECT_DOUBLE_EQ(banded.band.max, 4e-6);
  // Band ±1.3 m/s: also day 4 (8.0 m/s, 3e-6) → 2, 3, 4 (·1e-6): median 3e-6, mean 3e-6.
  const auto wider = app::fatigue::day_distribution(days, 0, 86400.0, 6.75, 2, 1.3);
  EXPECT_EQ(wider.band.count, 3u);
  EXPECT_DOUBLE_EQ(wider.band.median, 3e-6);
  EXPECT_DOUBLE_EQ(wider.band.mean, 3e-6);
  EXPECT_DOUBLE_EQ(wider.band.q1, 2.5e-6);
}

TEST(ProgressBar, IsDrawnOnATerminalButNotIntoAPipeOrWhenSwitchedOff) {
  // Arrange: a pipe (as in CI logs and `| tee`) and a pseudo-terminal.
  int pipe_fds[2];
  ASSERT_EQ(::pipe(pipe_fds), 0);
  const int master = ::posix_openpt(O_RDWR | O_NOCTTY);
  ASSERT_GE(master, 0);
  ASSERT_EQ(::grantpt(master), 0);
  ASSERT_EQ(::unlockpt(master), 0);
  const int tty = ::open(::ptsname(master), O_RDWR | O_NOCTTY);
  ASSERT_GE(tty, 0);
  // Act / Assert
  EXPECT_FALSE(app::fatigue::show_progress(false, pipe_fds[1]));
  EXPECT_TRUE(app::fatigue::show_progress(false, tty));
  EXPECT_FALSE(app::fatigue::show_progress(true, tty));
  ::close(tty);
  ::close(master);
  ::close(pipe_fds[0]);
  ::close(pipe_fds[1]);
}

TEST(ProgressLine, RedrawsOneLineWithCountAndShareAndEndsItOnceOrStaysSilent) {
  // Arrange: a temporary file stands for the terminal.
  std::FILE* out = std::tmpfile();
  ASSERT_NE(out, nullptr);
  {
    app::fatigue::ProgressLine line(true, "load spectrum", "points", 8.0, out);
    line.update(2.0);  // the first update draws at once
    line.update(8.0);  // within 0.25 s: not drawn, but finish() draws the final count
    line.finish();
    line.finish();  // a second finish (and the destructor) add nothing
  }
  app::fatigue::ProgressLine silent(false, "off", "rows", 8.0, out);
  silent.update(4.0);
  silent.finish();
  // Assert
  std::rewind(out);
  std::string text(512, '\0');
  text.resize(std::fread(text.data(), 1, text.size(), out));
  std::fclose(out);
  EXPECT_NE(text.find("\rload spectrum: 2/8 points   25.0 %"), std::string::npos) << text;
  EXPECT_NE(text.find("\rload spectrum: 8/8 points  100.0 %"), std::string::npos) << text;
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << text;
  EXPECT_EQ(text.back(), '\n');
  EXPECT_EQ(text.find("off"), std::string::npos) << text;
}

TEST(ElapsedTicker, DrawsTheElapsedTimeWhileItLivesAndNothingWhenDisabled) {
  std::FILE* out = std::tmpfile();
  ASSERT_NE(out, nullptr);
  {
    const app::fatigue::ElapsedTicker ticker(true, "simulating", out);
    // The first tick comes after 0.5 s; wait for it (a loaded machine may delay it).
    for (int i = 0; i < 400 && std::ftell(out) <= 0; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  { const app::fatigue::ElapsedTicker silent(false, "off", out); }
  std::rewind(out);
  std::string text(512, '\0');
  text.resize(std::fread(text.data(), 1, text.size(), out));
  std::fclose(out);
  EXPECT_EQ(text.rfind("\rsimulating: ", 0), 0u) << text;
  EXPECT_NE(text.find(" s   \n"), std::string::npos) << text;  // the last draw, then the end
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << text;
  EXPECT_EQ(text.find("off"), std::string::npos) << text;
}

}  // namespace
