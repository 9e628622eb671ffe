// GPIO backends against a gpio-sim chip inside the rig: the keyphasor line is
// toggled from the simulator side at a known rate and the speed measured back
// from kernel-stamped edges; the watchdog and alarm outputs are read back from
// the simulator (and with gpioget after release).
#include <atomic>
#include <thread>

#include "hal/gpiod_lines.hpp"
#include "rig_env.hpp"

namespace {

using namespace std::chrono_literals;
using hal::Status;

std::string sim_attr(const std::string& line_env, const char* fallback, const char* attr) {
  return rig::env("DRIVETWIN_RIG_GPIOSIM_DIR") + "/sim_gpio" +
         rig::env(line_env.c_str(), fallback) + "/" + attr;
}

unsigned line_of(const char* name, unsigned fallback) {
  const std::string v = rig::env(name);
  return v.empty() ? fallback : static_cast<unsigned>(std::stoul(v));
}

TEST(RigGpio, MeasuresTheKeyphasorSpeedFromLinesToggledAtAKnownRate) {
  RIG_SKIP_OUTSIDE();
  // Arrange: keyphasor on the sim chip, rising edges; a thread toggles the pull at 10 Hz
  // (period 100 ms: rising edge every 100 ms) on absolute deadlines so jitter does not accumulate.
  hal::GpiodKeyphasorConfig c;
  c.chip.chip = rig::env("DRIVETWIN_RIG_GPIOCHIP", "/dev/gpiochip0");
  c.line = line_of("DRIVETWIN_RIG_KEYPHASOR_LINE", 0);
  hal::GpiodKeyphasor kp(c);
  ASSERT_EQ(kp.configure(), Status::kOk);
  ASSERT_EQ(kp.activate(), Status::kOk);
  const std::string pull = sim_attr("DRIVETWIN_RIG_KEYPHASOR_LINE", "0", "pull");
  ASSERT_TRUE(rig::write_text(pull, "pull-down"));
  constexpr int kRevolutions = 20;
  constexpr auto kPeriod = 100ms;
  std::thread toggler([&] {
    auto t = std::chrono::steady_clock::now() + kPeriod;
    for (int i = 0; i < kRevolutions; ++i) {
      std::this_thread::sleep_until(t);
      rig::write_text(pull, "pull-up");
      std::this_thread::sleep_until(t + kPeriod / 2);
      rig::write_text(pull, "pull-down");
      t += kPeriod;
    }
  });

  // Act: feed the edges to the tracker as the loop would
  hal::KeyphasorTracker tracker;
  std::vector<hal::KeyphasorEdge> edges;
  const bool all = rig::wait_until(
      [&] {
        hal::KeyphasorEdge e;
        while (kp.read(e) != Status::kNoData) {
          tracker.on_edge(e);
          edges.push_back(e);
        }
        return edges.size() >= static_cast<std::size_t>(kRevolutions);
      },
      20000ms);
  toggler.join();

  // Assert: the mean rate over all edges is 10 Hz (kernel stamps; the writer's
  // jitter does not accumulate with absolute deadlines): within 5 %.
  ASSERT_TRUE(all) << edges.size() << " edges";
  const double span_s =
      std::chrono::duration<double>(edges.back().stamp - edges.front().stamp).count();
  const double mean_hz = static_cast<double>(edges.size() - 1) / span_s;
  EXPECT_NEAR(mean_hz, 10.0, 0.5);
  const auto s = tracker.state(edges.back().stamp);
  EXPECT_EQ(s.edges, static_cast<std::uint32_t>(kRevolutions));
  EXPECT_NEAR(s.speed_hz, 10.0,
              3.0);  // last single period: scheduling jitter of the toggler under TCG
  // A stuck keyphasor: no more edges → invalid after two periods
  EXPECT_FALSE(tracker.state(edges.back().stamp + 300ms).valid);
}

TEST(RigGpio, DrivesTheWatchdogAndAlarmRelayAndFallsToSafeStates) {
  RIG_SKIP_OUTSIDE();
  // Arrange
  hal::GpiodOutputsConfig c;
  c.chip.chip = rig::env("DRIVETWIN_RIG_GPIOCHIP", "/dev/gpiochip0");
  c.watchdog_line = line_of("DRIVETWIN_RIG_WATCHDOG_LINE", 1);
  c.alarm_line = line_of("DRIVETWIN_RIG_ALARM_LINE", 2);
  const std::string wd = sim_attr("DRIVETWIN_RIG_WATCHDOG_LINE", "1", "value");
  const std::string alarm = sim_attr("DRIVETWIN_RIG_ALARM_LINE", "2", "value");
  auto out = std::make_unique<hal::GpiodDigitalOutputs>(c);

  // Act / Assert: configured straight into the safe states
  ASSERT_EQ(out->configure(), Status::kOk);
  EXPECT_EQ(rig::read_text(wd), "0");
  EXPECT_EQ(rig::read_text(alarm), "0");  // relay de-energised = alarm raised
  ASSERT_EQ(out->activate(), Status::kOk);

  // the loop toggles the watchdog: each level is seen on the line
  for (int i = 0; i < 10; ++i) {
    const bool level = (i % 2) == 0;
    ASSERT_EQ(out->set_watchdog(level), Status::kOk);
    EXPECT_EQ(rig::read_text(wd), level ? "1" : "0") << "toggle " << i;
  }
  // healthy: relay energised; alarm: de-energised
  ASSERT_EQ(out->set_alarm(false), Status::kOk);
  EXPECT_EQ(rig::read_text(alarm), "1");
  ASSERT_EQ(out->set_alarm(true), Status::kOk);
  EXPECT_EQ(rig::read_text(alarm), "0");
  ASSERT_EQ(out->set_alarm(false), Status::kOk);
  ASSERT_EQ(out->set_watchdog(true), Status::kOk);

  // deactivate: safe states while the lines stay held
  EXPECT_EQ(out->deactivate(), Status::kOk);
  EXPECT_EQ(rig::read_text(wd), "0");
  EXPECT_EQ(rig::read_text(alarm), "0");
  EXPECT_EQ(out->set_watchdog(true), Status::kWrongState);

  // released: gpioget reads the line's pull (pull-down: relay off = alarm raised)
  out.reset();
  rig::write_text(sim_attr("DRIVETWIN_RIG_ALARM_LINE", "2", "pull"), "pull-down");
  const std::string got =
      rig::sh("gpioget " + rig::env("DRIVETWIN_RIG_GPIOCHIP_NAME", "gpiochip0") + " " +
              std::to_string(c.alarm_line));
  EXPECT_EQ(got.substr(0, 1), "0") << got;
}

TEST(RigGpio, RefusesALineAnotherConsumerHolds) {
  RIG_SKIP_OUTSIDE();
  // Arrange: the outputs hold the watchdog line
  hal::GpiodOutputsConfig oc;
  oc.chip.chip = rig::env("DRIVETWIN_RIG_GPIOCHIP", "/dev/gpiochip0");
  oc.watchdog_line = line_of("DRIVETWIN_RIG_WATCHDOG_LINE", 1);
  oc.alarm_line = line_of("DRIVETWIN_RIG_ALARM_LINE", 2);
  hal::GpiodDigitalOutputs out(oc);
  ASSERT_EQ(out.configure(), Status::kOk);
  hal::GpiodKeyphasorConfig kc;
  kc.chip = oc.chip;
  kc.line = oc.watchdog_line;
  hal::GpiodKeyphasor kp(kc);

  // Act / Assert
  EXPECT_EQ(kp.configure(), Status::kIoError);
}

}  // namespace
