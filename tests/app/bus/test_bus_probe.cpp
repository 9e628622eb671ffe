// `drivetwin bus probe` against the simulated buses (stepped clock: quick and
// deterministic), a real libmodbus controller on loopback, and a replayed bundle.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>

#include "bus/bus_config.hpp"
#include "bus/probe.hpp"
#include "hal/recording_bundle.hpp"
#include "modbus_test_util.hpp"

namespace {

TEST(BusProbe, PrintsSimulatedScadaCmsAndKeyphasorEverySecond) {
  // Arrange
  const auto c = app::bus::parse_bus_config(
      "format = \"drivetwin-bus/1\"\n[scada]\nbackend = \"sim\"\n[cms]\nbackend = \"sim\"\n"
      "[keyphasor]\nbackend = \"sim\"\n[outputs]\nbackend = \"memory\"\n",
      "sim.toml");
  app::bus::ProbeOptions o;
  o.seconds = 2.0;
  o.fast = true;
  std::ostringstream out;

  // Act
  const int status = app::bus::run_probe(c, o, out);

  // Assert: 25.6 kHz / 28 samples per block = 914.3 blocks/s per channel;
  // hss 14.3032 Hz = 858.2 rpm; the paper point's wind speed with its unit
  const std::string s = out.str();
  EXPECT_EQ(status, 0) << s;
  EXPECT_NE(s.find("[    2.0 s]"), std::string::npos) << s;
  EXPECT_NE(s.find("wind_speed_mps"), std::string::npos) << s;
  EXPECT_NE(s.find(" m/s "), std::string::npos) << s;
  EXPECT_NE(s.find("ch0=914"), std::string::npos) << s;
  EXPECT_NE(s.find("hss 14.3032 Hz = 858.2 rpm"), std::string::npos) << s;
  EXPECT_NE(s.find("held in their safe states"), std::string::npos) << s;
}

TEST(BusProbe, ShowsInjectedCmsGapsAndReportsASilentBus) {
  // Arrange
  const auto gaps = app::bus::parse_bus_config(
      "format = \"drivetwin-bus/1\"\n[cms]\nbackend = \"sim\"\nfault = \"gaps\"\n", "gaps.toml");
  const auto silent = app::bus::parse_bus_config(
      "format = \"drivetwin-bus/1\"\n[cms]\nbackend = \"sim\"\nfault = \"silent\"\n",
      "silent.toml");
  app::bus::ProbeOptions o;
  o.seconds = 1.0;
  o.fast = true;
  std::ostringstream out_gaps, out_silent;

  // Act
  const int st_gaps = app::bus::run_probe(gaps, o, out_gaps);
  const int st_silent = app::bus::run_probe(silent, o, out_silent);

  // Assert: frames k = 0..914 have t0 <= 1 s (1093.75 µs apart); every 4th (k = 3, 7, … 911)
  // is lost: 228 per channel, 2 channels → 456 gaps of one frame; 687 blocks/s per channel
  // arrive. Silent → exit 3.
  EXPECT_EQ(st_gaps, 0);
  EXPECT_NE(out_gaps.str().find("cms: gap"), std::string::npos) << out_gaps.str();
  EXPECT_NE(out_gaps.str().find("ch0=687"), std::string::npos) << out_gaps.str();
  EXPECT_NE(out_gaps.str().find("gaps 456 (lost 456)"), std::string::npos) << out_gaps.str();
  EXPECT_EQ(st_silent, 3);
  EXPECT_NE(out_silent.str().find("no data from: cms"), std::string::npos) << out_silent.str();
}

TEST(BusProbe, ReadsARealModbusControllerWithTheConfiguredMap) {
  // Arrange: wind 6.75 m/s as uint16 × 0.01 at register 0, torque as float32 at 8
  modbus_test::PeerServer peer;
  peer.set_holding(0, 675);
  peer.set_holding(8, 0x48B0);  // 361747.0f
  peer.set_holding(9, 0xA260);
  const std::string toml =
      "format = \"drivetwin-bus/1\"\n[scada]\nbackend = \"modbus\"\nhost = \"127.0.0.1\"\nport = " +
      std::to_string(peer.port()) +
      "\npoll_period_ms = 100\n"
      "[[scada.register]]\nquantity = \"wind_speed_mps\"\naddress = 0\nscale = 0.01\nunit = "
      "\"m/s\"\n"
      "[[scada.register]]\nquantity = \"torque_nm\"\naddress = 8\ntype = \"float32\"\nunit = "
      "\"N·m\"\n";
  const auto c = app::bus::parse_bus_config(toml, "live.toml");
  app::bus::ProbeOptions o;
  o.seconds = 0.6;
  o.report_every = std::chrono::milliseconds(300);
  std::ostringstream out;

  // Act
  const int status = app::bus::run_probe(c, o, out);

  // Assert
  const std::string s = out.str();
  EXPECT_EQ(status, 0) << s;
  EXPECT_NE(s.find("scada: ok"), std::string::npos) << s;
  EXPECT_NE(s.find("wind_speed_mps                 6.750 m/s"), std::string::npos) << s;
  EXPECT_NE(s.find("torque_nm                 361747.000 N·m"), std::string::npos) << s;
}

TEST(BusProbe, ReplaysABundleAtItsRecordedRate) {
  // Arrange: 1 s at 2.8 kHz of two channels → 100 blocks of 28 per channel
  const auto dir =
      std::filesystem::temp_directory_path() / ("drivetwin-probe-" + std::to_string(::getpid()));
  hal::Recording r;
  r.sample_rate_hz = 2800;
  r.channels = {{"point1", "b5", "radial", "", "m/s^2"}, {"point2", "b3", "radial", "", "m/s^2"}};
  r.operating_point.rotor_speed_rpm = 8.33;
  r.operating_point.wind_speed_mps = 6.75;
  r.samples.assign(2, std::vector<double>(2800, 0.5));
  r.scada = {{0.0, 6.75, 8.33, std::nullopt, std::nullopt, std::nullopt}};
  ASSERT_FALSE(hal::write_bundle(dir, r));
  const auto c = app::bus::parse_bus_config(
      "format = \"drivetwin-bus/1\"\n[replay]\nbundle = \"" + dir.string() +
          "\"\n[scada]\nbackend = \"replay\"\n[cms]\nbackend = \"replay\"\n",
      "replay.toml");
  app::bus::ProbeOptions o;
  o.seconds = 1.0;
  o.fast = true;
  std::ostringstream out;

  // Act
  const int status = app::bus::run_probe(c, o, out);
  std::filesystem::remove_all(dir);

  // Assert
  const std::string s = out.str();
  EXPECT_EQ(status, 0) << s;
  EXPECT_NE(s.find("point1=100 [m/s^2] point2=100 [m/s^2]"), std::string::npos) << s;
  EXPECT_NE(s.find("rotor_speed_rpm                8.330 rpm"), std::string::npos) << s;
}

// ---- issue 15: stale, stuck, inconsistent, and one bus failing -------------------------

// Runs the probe on a config text for `seconds` of stepped time; returns status and output.
std::pair<int, std::string> probe(const std::string& text, double seconds = 2.0, bool fast = true) {
  const auto c = app::bus::parse_bus_config(text, "probe.toml");
  app::bus::ProbeOptions o;
  o.seconds = seconds;
  o.fast = fast;
  std::ostringstream out;
  const int status = app::bus::run_probe(c, o, out);
  return {status, out.str()};
}

const char* const kAllSim =
    "format = \"drivetwin-bus/1\"\n[scada]\nbackend = \"sim\"\n[cms]\nbackend = \"sim\"\n"
    "[keyphasor]\nbackend = \"sim\"\n";

TEST(BusProbe, EveryRedundantSpeedAgreesOnTheSimulatedPaperPoint) {
  // The simulated buses at the paper point: SCADA rotor 8.33 rpm (noisy), generator speed
  // 8.33 × 103.0246, keyphasor at 14.3032 Hz on the hss (= 8.33 rpm through the ratio
  // (1 + 99/21)·92/21·107/26), CMS tone at the 371.884 Hz high-speed mesh (26 teeth × hss).
  const auto [status, s] = probe(kAllSim);
  EXPECT_EQ(status, 0) << s;
  EXPECT_NE(s.find("keyphasor on hss (pulses_per_rev 1) 8.33;"), std::string::npos) << s;
  EXPECT_NE(s.find("CMS mesh lines of ch0, ch1 (25600 Hz) 8.33;"), std::string::npos) << s;
  EXPECT_NE(s.find("nothing stale, stuck or inconsistent"), std::string::npos) << s;
}

TEST(BusProbe, AWrongPulsesPerRevIsCaughtByTheSpeedCrossCheck) {
  // One pulse per hss revolution read as two: 7.15 Hz = 429 rpm on the hss, half of what
  // SCADA's generator speed (858 rpm), its rotor speed and the CMS mesh line say.
  const auto [status, s] =
      probe(std::string(kAllSim) + "pulses_per_rev = 2\n");  // appended to [keyphasor]
  EXPECT_EQ(status, 4) << s;
  EXPECT_NE(s.find("speeds disagree: keyphasor on hss (pulses_per_rev 2) gives 4.165 rotor rpm, "
                   "0.5 (1/2) x the 8.3"),
            std::string::npos)
      << s;
  EXPECT_NE(s.find("look at: keyphasor.pulses_per_rev"), std::string::npos) << s;
}

TEST(BusProbe, AStuckCmsStreamExitsNonZeroSayingWhatToLookAt) {
  const auto [status, s] =
      probe("format = \"drivetwin-bus/1\"\n[cms]\nbackend = \"sim\"\nfault = \"stuck\"\n");
  EXPECT_EQ(status, 4) << s;
  EXPECT_NE(s.find("cms: stale at the end of the probe after"), std::string::npos) << s;
  EXPECT_NE(s.find("duplicate blocks"), std::string::npos) << s;
  EXPECT_NE(s.find("look at: the CMS front end"), std::string::npos) << s;
}

TEST(BusProbe, FrozenScadaValuesAreReportedStuck) {
  // A SCADA export replayed whose wind and rotor speed never change (a frozen register block).
  const auto dir = std::filesystem::temp_directory_path() /
                   ("drivetwin-probe-stuck-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::string csv = "t_s,wind_speed_mps,rotor_speed_rpm\n";
  for (int i = 0; i < 10; ++i) csv += std::to_string(i) + ",6.75,8.33\n";
  std::ofstream(dir / "scada.csv") << csv;
  const auto [status, s] =
      probe("format = \"drivetwin-bus/1\"\n[scada]\nbackend = \"replay\"\ncsv = \"" +
                (dir / "scada.csv").string() + "\"\n",
            6.0);
  std::filesystem::remove_all(dir);
  EXPECT_EQ(status, 4) << s;
  EXPECT_NE(s.find("scada: stuck: wind and rotor speed identical in"), std::string::npos) << s;
}

TEST(BusProbe, AMissingCanInterfaceDoesNotStopTheOtherBuses) {
  const auto [status, s] = probe(
      "format = \"drivetwin-bus/1\"\n[scada]\nbackend = \"sim\"\n[cms]\nbackend = "
      "\"socketcan\"\ninterface = \"nosuchcan0\"\n[[cms.channel]]\nid = 0\nname = "
      "\"point1\"\nscale = 0.001\nunit = \"m/s^2\"\n[keyphasor]\nbackend = \"sim\"\n",
      1.0, /*fast=*/false);  // a live bus: real time
  EXPECT_EQ(status, 4) << s;
  EXPECT_NE(s.find("cms: FAILED to open"), std::string::npos) << s;
  EXPECT_NE(s.find("look at: the CAN interface nosuchcan0"), std::string::npos) << s;
  // ... and SCADA and the keyphasor were still probed.
  EXPECT_NE(s.find("wind_speed_mps"), std::string::npos) << s;
  EXPECT_NE(s.find("keyphasor: hss 14.3032 Hz"), std::string::npos) << s;
}

}  // namespace
