// The rig proves itself: a cross-built program opens the rig's CAN interfaces with
// raw SocketCAN sockets and the gpio-sim chip with libgpiod v1, and checks what the
// kernel peers do against what the kernel documents (Documentation/networking/can.rst,
// Documentation/admin-guide/gpio/gpio-sim.rst). It runs inside the emulated aarch64
// system (tools/rig/README.md gives the environment); anywhere else it skips.
//
// Thread context: single-threaded test code; blocking calls are bounded by poll()
// timeouts so a broken rig fails instead of hanging.

#include <fcntl.h>
#include <gpiod.h>
#include <gtest/gtest.h>
#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

namespace {

constexpr int kReceiveTimeoutMs = 2000;

// The value of a rig environment variable; empty outside the rig.
std::string rig_env(const char* name) {
  const char* v = std::getenv(name);
  return v != nullptr ? std::string(v) : std::string();
}

#define SKIP_OUTSIDE_RIG()                                                 \
  do {                                                                     \
    if (rig_env("DRIVETWIN_RIG") != "1") {                                 \
      GTEST_SKIP() << "not inside the emulated rig (DRIVETWIN_RIG unset)"; \
    }                                                                      \
  } while (0)

// A raw CAN socket bound to one interface, closed on scope exit.
class RawCanSocket {
 public:
  RawCanSocket(const std::string& ifname, bool fd_frames) {
    fd_ = ::socket(PF_CAN, SOCK_RAW, CAN_RAW);
    if (fd_ < 0) {
      error_ = "socket(PF_CAN): " + std::string(std::strerror(errno));
      return;
    }
    const int enable = fd_frames ? 1 : 0;
    if (::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &enable, sizeof enable) != 0) {
      error_ = "CAN_RAW_FD_FRAMES: " + std::string(std::strerror(errno));
      return;
    }
    sockaddr_can addr{};
    addr.can_family = AF_CAN;
    addr.can_ifindex = static_cast<int>(::if_nametoindex(ifname.c_str()));
    if (addr.can_ifindex == 0) {
      error_ = "no interface '" + ifname + "'";
      return;
    }
    if (::bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
      error_ = "bind(" + ifname + "): " + std::string(std::strerror(errno));
    }
  }
  ~RawCanSocket() {
    if (fd_ >= 0) ::close(fd_);
  }
  RawCanSocket(const RawCanSocket&) = delete;
  RawCanSocket& operator=(const RawCanSocket&) = delete;

  const std::string& error() const { return error_; }
  int fd() const { return fd_; }

  // Reads one frame into buf; returns the byte count, 0 on timeout, -1 on error.
  ssize_t receive(void* buf, std::size_t size) const {
    pollfd p{fd_, POLLIN, 0};
    const int r = ::poll(&p, 1, kReceiveTimeoutMs);
    if (r <= 0) return r;
    return ::read(fd_, buf, size);
  }

 private:
  int fd_ = -1;
  std::string error_;
};

std::int64_t monotonic_ns() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// Writes a word into a gpio-sim simulator attribute (sim_gpioN/pull).
bool write_sysfs(const std::string& path, const std::string& word) {
  const int fd = ::open(path.c_str(), O_WRONLY);
  if (fd < 0) return false;
  const bool ok = ::write(fd, word.data(), word.size()) == static_cast<ssize_t>(word.size());
  ::close(fd);
  return ok;
}

// Reads the first character of a gpio-sim simulator attribute (sim_gpioN/value).
char read_sysfs_char(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) return '?';
  char c = '?';
  if (::read(fd, &c, 1) != 1) c = '?';
  ::close(fd);
  return c;
}

// The rig's gpio-sim chip, opened by the path the rig exports.
struct Chip {
  gpiod_chip* chip = gpiod_chip_open(rig_env("DRIVETWIN_RIG_GPIOCHIP").c_str());
  ~Chip() {
    if (chip != nullptr) gpiod_chip_close(chip);
  }
};

unsigned selftest_line() {
  return static_cast<unsigned>(std::atoi(rig_env("DRIVETWIN_RIG_SELFTEST_LINE").c_str()));
}

std::string sim_attr(unsigned line, const char* attr) {
  return rig_env("DRIVETWIN_RIG_GPIOSIM_DIR") + "/sim_gpio" + std::to_string(line) + "/" + attr;
}

}  // namespace

TEST(RigCan, AnFdFrameSentOnVcan0ArrivesBitExactAtASecondSocket) {
  SKIP_OUTSIDE_RIG();
  // Arrange: two raw sockets on the FD-capable bus; vcan echoes a frame to every
  // other socket on the interface.
  const std::string bus = rig_env("DRIVETWIN_RIG_CAN");
  RawCanSocket sender(bus, true);
  RawCanSocket receiver(bus, true);
  ASSERT_EQ(sender.error(), "");
  ASSERT_EQ(receiver.error(), "");
  canfd_frame out{};
  out.can_id = 0x1F334455U | CAN_EFF_FLAG;
  out.len = CANFD_MAX_DLEN;
  out.flags = CANFD_BRS;
  for (std::size_t i = 0; i < CANFD_MAX_DLEN; ++i)
    out.data[i] = static_cast<std::uint8_t>(3 * i + 1);

  // Act
  const ssize_t sent = ::write(sender.fd(), &out, CANFD_MTU);
  canfd_frame in{};
  const ssize_t got = receiver.receive(&in, sizeof in);

  // Assert: the whole CANFD_MTU structure, same id, length, BRS flag and payload.
  ASSERT_EQ(sent, static_cast<ssize_t>(CANFD_MTU)) << std::strerror(errno);
  ASSERT_EQ(got, static_cast<ssize_t>(CANFD_MTU));
  EXPECT_EQ(in.can_id, out.can_id);
  EXPECT_EQ(in.len, out.len);
  EXPECT_NE(in.flags & CANFD_BRS, 0);
  EXPECT_EQ(std::memcmp(in.data, out.data, CANFD_MAX_DLEN), 0);
}

TEST(RigCan, TheClassicBusCarriesClassicFramesAndRefusesFdFrames) {
  SKIP_OUTSIDE_RIG();
  // Arrange: the classic-only bus (mtu 16): the kernel refuses a CANFD_MTU write
  // with EINVAL (net/can/raw.c, raw_sendmsg) even from an FD-enabled socket.
  const std::string bus = rig_env("DRIVETWIN_RIG_CAN_CLASSIC");
  RawCanSocket sender(bus, true);
  RawCanSocket receiver(bus, false);
  ASSERT_EQ(sender.error(), "");
  ASSERT_EQ(receiver.error(), "");
  can_frame classic{};
  classic.can_id = 0x5A1;
  classic.len = 8;
  const std::array<std::uint8_t, 8> payload{0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88};
  std::memcpy(classic.data, payload.data(), payload.size());
  canfd_frame fd{};
  fd.can_id = 0x123;
  fd.len = 12;

  // Act
  const ssize_t sent_classic = ::write(sender.fd(), &classic, CAN_MTU);
  can_frame in{};
  const ssize_t got = receiver.receive(&in, sizeof in);
  const ssize_t sent_fd = ::write(sender.fd(), &fd, CANFD_MTU);
  const int fd_errno = errno;

  // Assert
  ASSERT_EQ(sent_classic, static_cast<ssize_t>(CAN_MTU));
  ASSERT_EQ(got, static_cast<ssize_t>(CAN_MTU));
  EXPECT_EQ(in.can_id, 0x5A1U);
  EXPECT_EQ(in.len, 8);
  EXPECT_EQ(std::memcmp(in.data, payload.data(), payload.size()), 0);
  EXPECT_EQ(sent_fd, -1);
  EXPECT_EQ(fd_errno, EINVAL);
}

TEST(RigGpio, TheContractLinesAreFoundByNameAtTheirOffsets) {
  SKIP_OUTSIDE_RIG();
  // Arrange
  Chip c;
  ASSERT_NE(c.chip, nullptr) << rig_env("DRIVETWIN_RIG_GPIOCHIP");
  const std::array<std::pair<const char*, const char*>, 3> contract{{
      {"keyphasor", "DRIVETWIN_RIG_KEYPHASOR_LINE"},
      {"watchdog", "DRIVETWIN_RIG_WATCHDOG_LINE"},
      {"alarm_relay", "DRIVETWIN_RIG_ALARM_LINE"},
  }};

  for (const auto& [name, env] : contract) {
    // Act
    gpiod_line* line = gpiod_chip_find_line(c.chip, name);

    // Assert
    ASSERT_NE(line, nullptr) << name;
    EXPECT_EQ(std::to_string(gpiod_line_offset(line)), rig_env(env)) << name;
  }
}

TEST(RigGpio, EveryPullToggleGivesOneEdgeStampedBetweenTheWriteAndItsRead) {
  SKIP_OUTSIDE_RIG();
  // Arrange: the rig's own line, pulled down, requested for both edges.
  constexpr int kToggles = 20;
  const unsigned offset = selftest_line();
  const std::string pull = sim_attr(offset, "pull");
  ASSERT_TRUE(write_sysfs(pull, "pull-down")) << pull;
  Chip c;
  ASSERT_NE(c.chip, nullptr);
  gpiod_line* line = gpiod_chip_get_line(c.chip, offset);
  ASSERT_NE(line, nullptr);
  ASSERT_EQ(gpiod_line_request_both_edges_events(line, "rig_selfcheck"), 0) << std::strerror(errno);

  std::vector<std::int64_t> before_ns, after_ns, edge_ns;
  std::vector<int> type;
  for (int i = 0; i < kToggles; ++i) {
    // Act: one pull change, then its event.
    before_ns.push_back(monotonic_ns());
    ASSERT_TRUE(write_sysfs(pull, i % 2 == 0 ? "pull-up" : "pull-down"));
    const timespec timeout{2, 0};
    ASSERT_EQ(gpiod_line_event_wait(line, &timeout), 1) << "no edge for toggle " << i;
    gpiod_line_event ev{};
    ASSERT_EQ(gpiod_line_event_read(line, &ev), 0);
    after_ns.push_back(monotonic_ns());
    edge_ns.push_back(static_cast<std::int64_t>(ev.ts.tv_sec) * 1'000'000'000 + ev.ts.tv_nsec);
    type.push_back(ev.event_type);
  }
  const timespec short_wait{0, 100'000'000};
  const int extra = gpiod_line_event_wait(line, &short_wait);
  gpiod_line_release(line);

  // Assert: rising, falling, rising, ...; each kernel stamp (CLOCK_MONOTONIC for the
  // v1 uAPI) lies between the write that caused it and the read that fetched it,
  // and no spurious event follows.
  for (int i = 0; i < kToggles; ++i) {
    EXPECT_EQ(type[i], i % 2 == 0 ? GPIOD_LINE_EVENT_RISING_EDGE : GPIOD_LINE_EVENT_FALLING_EDGE)
        << i;
    EXPECT_GE(edge_ns[i], before_ns[i]) << i;
    EXPECT_LE(edge_ns[i], after_ns[i]) << i;
  }
  EXPECT_EQ(extra, 0);
}

TEST(RigGpio, AnOutputDrivenThroughLibgpiodReadsBackOnTheSimulatorSide) {
  SKIP_OUTSIDE_RIG();
  // Arrange
  const unsigned offset = selftest_line();
  const std::string value = sim_attr(offset, "value");
  Chip c;
  ASSERT_NE(c.chip, nullptr);
  gpiod_line* line = gpiod_chip_get_line(c.chip, offset);
  ASSERT_NE(line, nullptr);
  ASSERT_EQ(gpiod_line_request_output(line, "rig_selfcheck", 0), 0) << std::strerror(errno);

  // Act
  const char initial = read_sysfs_char(value);
  ASSERT_EQ(gpiod_line_set_value(line, 1), 0);
  const char high = read_sysfs_char(value);
  ASSERT_EQ(gpiod_line_set_value(line, 0), 0);
  const char low = read_sysfs_char(value);
  gpiod_line_release(line);

  // Assert
  EXPECT_EQ(initial, '0');
  EXPECT_EQ(high, '1');
  EXPECT_EQ(low, '0');
}
