// The SCADA interpolator (app/signal/scada_interpolator.hpp): through every sample at its
// time (plus the delay), the exact line through a ramp, monotone across a step (no
// overshoot), flat at a sampled extreme, hold and one-period transition around a gap, and
// the hold past the newest sample.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "signal/scada_interpolator.hpp"

namespace {

using app::signal::ScadaInterpolator;
hal::Timestamp at_s(double t) {
  return hal::Timestamp{static_cast<std::int64_t>(std::llround(t * 1e9))};
}

// Online, as the loop runs it: samples f(k) at whole seconds, the value read every 10 ms.
template <class F, class Check>
void online(ScadaInterpolator& s, F f, double end_s, Check check) {
  int next = 0;
  for (int i = 0; i <= static_cast<int>(std::llround(end_s * 100)); ++i) {
    const double t = 0.01 * i;
    while (next <= t + 1e-9) {
      s.sample(at_s(next), f(next));
      ++next;
    }
    check(t, s.at(at_s(t)));
  }
}

TEST(ScadaInterpolator, PassesThroughEverySampleOneDelayLaterAndFollowsARampExactly) {
  ScadaInterpolator s(1.0);
  EXPECT_DOUBLE_EQ(s.delay_s(), 2.0);
  online(
      s,
      [](int k) {
        return model::dynamics::RomInputs{10.0, 1000.0 + 50.0 * k};
      },
      20.0,
      [](double t, const model::dynamics::RomInputs& v) {
        if (t >= 2.0) {
          EXPECT_NEAR(v.input_torque_nm, 1000.0 + 50.0 * (t - 2.0), 1e-6) << t;
        }
      });
}

TEST(ScadaInterpolator, CrossesAStepMonotonicallyInOnePeriodWithoutOvershoot) {
  ScadaInterpolator s(1.0);
  double prev = 500.0;
  online(
      s,
      [](int k) {
        return model::dynamics::RomInputs{10.0, k < 5 ? 500.0 : 800.0};
      },
      12.0,
      [&](double t, const model::dynamics::RomInputs& in) {
        const double v = in.input_torque_nm;
        EXPECT_GE(v, prev - 1e-9) << t;
        EXPECT_LE(v, 800.0 + 1e-9);
        if (t <= 6.0) {
          EXPECT_DOUBLE_EQ(v, 500.0) << t;  // sample 4, 2 s later
        }
        if (t >= 7.0) {
          EXPECT_DOUBLE_EQ(v, 800.0) << t;  // sample 5
        }
        prev = v;
      });
}

TEST(ScadaInterpolator, StaysFlatAtASampledPeak) {
  ScadaInterpolator s(1.0);
  const double v[] = {0, 1, 3, 3, 1, 0, 0, 0, 0, 0};
  online(
      s,
      [&](int k) {
        return model::dynamics::RomInputs{0.0, v[std::min(k, 9)]};
      },
      9.0,
      [](double t, const model::dynamics::RomInputs& in) {
        if (t >= 4.0 && t <= 5.0) {
          EXPECT_NEAR(in.input_torque_nm, 3.0, 1e-12) << t;
        }
        EXPECT_LE(in.input_torque_nm, 3.0 + 1e-12);
      });
}

TEST(ScadaInterpolator, HoldsThroughAGapThenTakesOnePeriodToTheNewValue) {
  ScadaInterpolator s(1.0);
  for (int k = 0; k <= 3; ++k) s.sample(at_s(k), {10.0, 100.0});
  s.sample(at_s(30.0), {12.0, 200.0});                        // 27 s silent
  EXPECT_DOUBLE_EQ(s.at(at_s(20.0)).input_torque_nm, 100.0);  // the hold (t − D = 18 s)
  EXPECT_DOUBLE_EQ(s.at(at_s(31.0)).input_torque_nm, 100.0);  // 29 s: one period before
  const double mid = s.at(at_s(31.5)).input_torque_nm;
  EXPECT_GT(mid, 100.0);
  EXPECT_LT(mid, 200.0);
  EXPECT_NEAR(s.at(at_s(32.0)).input_torque_nm, 200.0, 1e-9);
  EXPECT_DOUBLE_EQ(s.at(at_s(99.0)).rotor_speed_rpm, 12.0);  // past the newest: held
}

TEST(ScadaInterpolator, IgnoresASampleNotAfterTheNewestAndCountsIt) {
  ScadaInterpolator s(1.0);
  EXPECT_FALSE(s.started());
  s.sample(at_s(5.0), {1.0, 2.0});
  s.sample(at_s(5.0), {9.0, 9.0});
  s.sample(at_s(4.0), {9.0, 9.0});
  EXPECT_EQ(s.ignored(), 2u);
  EXPECT_DOUBLE_EQ(s.at(at_s(10.0)).input_torque_nm, 2.0);
}

}  // namespace
