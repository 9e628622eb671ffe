// SocketCanCmsStream against the kernel's vcan and can-utils inside the rig:
// frames from a peer raw socket and from cansend/cangen decoded, gaps and
// duplicates counted, error frames and bus-off reported and recovered from, the
// twin's heartbeat seen by candump.
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstring>

#include "hal/socketcan_cms_stream.hpp"
#include "rig_env.hpp"

namespace {

using namespace std::chrono_literals;
using hal::Status;

constexpr std::uint32_t kBase = 0x180;

/// The front end's side: a raw socket on the same vcan.
class Peer {
 public:
  Peer(const std::string& ifname, bool fd) {
    s_ = ::socket(PF_CAN, SOCK_RAW, CAN_RAW);
    const int on = fd ? 1 : 0;
    ::setsockopt(s_, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof on);
    ifreq ifr{};
    std::strncpy(ifr.ifr_name, ifname.c_str(), IFNAMSIZ - 1);
    ::ioctl(s_, SIOCGIFINDEX, &ifr);
    sockaddr_can a{};
    a.can_family = AF_CAN;
    a.can_ifindex = ifr.ifr_ifindex;
    ok_ = ::bind(s_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  }
  ~Peer() { ::close(s_); }
  bool ok() const { return ok_; }
  bool send(const hal::CanFrame& f) {
    canfd_frame k{};
    k.can_id = f.id;
    k.len = f.len;
    std::memcpy(k.data, f.data.data(), f.len);
    const std::size_t size = f.fd ? CANFD_MTU : CAN_MTU;
    return ::write(s_, &k, size) == static_cast<ssize_t>(size);
  }
  bool send_error(canid_t cls, std::uint8_t ctrl = 0) {
    can_frame k{};
    k.can_id = CAN_ERR_FLAG | cls;
    k.can_dlc = CAN_ERR_DLC;
    k.data[1] = ctrl;
    return ::write(s_, &k, sizeof k) == static_cast<ssize_t>(sizeof k);
  }

 private:
  int s_ = -1;
  bool ok_ = false;
};

hal::SocketCanConfig config(const std::string& ifname, bool fd) {
  hal::SocketCanConfig c;
  c.interface = ifname;
  c.fd = fd;
  c.base_id = kBase;
  c.scale.fill(0.0f);
  c.scale[0] = 0.001f;  // [m/s² per LSB]
  c.scale[1] = 0.5f;
  c.stale_after = 2000ms;
  c.error_hold = 200ms;
  return c;
}

hal::CanFrame fd_block(std::uint8_t ch, std::uint16_t seq, std::uint32_t t0_us,
                       std::int32_t first) {
  hal::CmsFrame b;
  b.channel = ch;
  b.sequence = seq;
  b.t0_us = t0_us;
  b.count = 28;
  for (std::size_t i = 0; i < b.count; ++i) b.raw[i] = first + static_cast<std::int32_t>(i);
  hal::CanFrame f;
  EXPECT_TRUE(hal::encode_cms_fd_frame(b, kBase, f));
  return f;
}

TEST(RigSocketCan, DecodesFdBlocksFromAPeerAndCountsGapsAndDuplicates) {
  RIG_SKIP_OUTSIDE();
  // Arrange
  const std::string can = rig::env("DRIVETWIN_RIG_CAN", "vcan0");
  hal::MonotonicClock clock;
  hal::SocketCanConfig c = config(can, true);
  c.error_hold = 3000ms;  // long enough for TCG emulation to finish sending before we look
  c.stale_after = 10000ms;
  hal::SocketCanCmsStream stream(c, clock);
  ASSERT_EQ(stream.configure(), Status::kOk) << "interface " << can;
  ASSERT_EQ(stream.activate(), Status::kOk);
  Peer peer(can, true);
  ASSERT_TRUE(peer.ok());

  // Act: sequences 0..39 on channel 0, without 20, with 30 sent twice; 1093.75 µs per block
  int sent = 0;
  for (std::uint16_t s = 0; s < 40; ++s) {
    if (s == 20) continue;
    ASSERT_TRUE(peer.send(fd_block(0, s, 1000000u + s * 1094u, 100 * s)));
    ++sent;
    if (s == 30) {
      ASSERT_TRUE(peer.send(fd_block(0, s, 1000000u + s * 1094u, 100 * s)));
    }
    std::this_thread::sleep_for(1ms);
  }
  std::vector<hal::CmsBlock> got;
  ASSERT_TRUE(rig::wait_until([&] {
    hal::CmsBlock b;
    while (stream.read(b) == Status::kOk) got.push_back(b);
    return got.size() >= static_cast<std::size_t>(sent);
  }));

  // Assert
  const auto st = stream.stats();
  EXPECT_EQ(got.size(), 39u);
  EXPECT_EQ(st.gaps, 1u);
  EXPECT_EQ(st.lost_blocks, 1u);
  EXPECT_EQ(st.duplicates, 1u);
  EXPECT_EQ(got[0].sequence, 0);
  EXPECT_FLOAT_EQ(got[1].samples[0], 0.1f);  // raw 100 × 0.001
  EXPECT_FLOAT_EQ(got[1].samples[27], 0.127f);
  EXPECT_EQ((got[1].stamp - got[0].stamp).count(), 1094 * 1000);
  EXPECT_EQ(stream.health(clock.now()), Status::kGap);  // the gap is shown for error_hold
  std::this_thread::sleep_for(3200ms);
  EXPECT_EQ(stream.health(clock.now()), Status::kOk);  // and clears without a restart
}

TEST(RigSocketCan, DecodesAFrameSentByCansend) {
  RIG_SKIP_OUTSIDE();
  // Arrange
  const std::string can = rig::env("DRIVETWIN_RIG_CAN", "vcan0");
  hal::MonotonicClock clock;
  hal::SocketCanCmsStream stream(config(can, true), clock);
  ASSERT_EQ(stream.configure(), Status::kOk);
  ASSERT_EQ(stream.activate(), Status::kOk);

  // Act: channel 1 (id 0x181): version 1|ch 1 = 11, int16 × 2 = 02, seq 5 = 0500,
  // t0 = 0, samples 10 (0A00) and -4 (FCFF): 12 bytes. "##0" = FD, no flags.
  const std::string out = rig::sh("cansend " + can + " 181##011020500000000000A00FCFF");
  hal::CmsBlock b;
  const bool got = rig::wait_until([&] { return stream.read(b) == Status::kOk; });

  // Assert
  ASSERT_TRUE(got) << out;
  EXPECT_EQ(b.channel, 1);
  EXPECT_EQ(b.sequence, 5);
  ASSERT_EQ(b.count, 2);
  EXPECT_FLOAT_EQ(b.samples[0], 5.0f);   // 10 × 0.5
  EXPECT_FLOAT_EQ(b.samples[1], -2.0f);  // −4 × 0.5
}

TEST(RigSocketCan, CountsEveryRandomCangenFrameAsDecodedOrMalformedWithoutStopping) {
  RIG_SKIP_OUTSIDE();
  // Arrange
  const std::string can = rig::env("DRIVETWIN_RIG_CAN", "vcan0");
  hal::MonotonicClock clock;
  hal::SocketCanCmsStream stream(config(can, true), clock);
  ASSERT_EQ(stream.configure(), Status::kOk);
  ASSERT_EQ(stream.activate(), Status::kOk);

  // Act: 100 CAN FD frames of random bytes and length on channel 0's id
  const std::string out = rig::sh("cangen " + can + " -I 180 -f -L r -D r -g 1 -n 100");
  const bool all = rig::wait_until([&] {
    hal::CmsBlock b;
    while (stream.read(b) == Status::kOk) {
    }
    const auto s = stream.stats();
    return s.blocks + s.malformed + s.duplicates + s.reordered >= 100;
  });

  // Assert: accounted for, and the stream still decodes a good frame afterwards
  EXPECT_TRUE(all) << out;
  Peer peer(can, true);
  ASSERT_TRUE(peer.send(fd_block(1, 0, 0, 0)));
  hal::CmsBlock b;
  EXPECT_TRUE(rig::wait_until([&] { return stream.read(b) == Status::kOk && b.channel == 1; }));
}

TEST(RigSocketCan, ReportsBusOffAndRecoversWhenTheControllerRestarts) {
  RIG_SKIP_OUTSIDE();
  // Arrange
  const std::string can = rig::env("DRIVETWIN_RIG_CAN", "vcan0");
  hal::MonotonicClock clock;
  hal::SocketCanCmsStream stream(config(can, true), clock);
  ASSERT_EQ(stream.configure(), Status::kOk);
  ASSERT_EQ(stream.activate(), Status::kOk);
  Peer peer(can, true);

  // Act 1: error-passive warning, then bus-off
  ASSERT_TRUE(peer.send_error(CAN_ERR_CRTL, CAN_ERR_CRTL_RX_PASSIVE));
  const bool bus_error =
      rig::wait_until([&] { return stream.health(clock.now()) == Status::kBusError; });
  ASSERT_TRUE(peer.send_error(CAN_ERR_BUSOFF));
  const bool off = rig::wait_until([&] { return stream.health(clock.now()) == Status::kBusOff; });
  hal::CmsBlock b;
  const Status read_while_off = stream.read(b);

  // Act 2: the controller restarts (restart-ms), then data flows again
  ASSERT_TRUE(peer.send_error(CAN_ERR_RESTARTED));
  const bool recovered =
      rig::wait_until([&] { return stream.health(clock.now()) != Status::kBusOff; });
  ASSERT_TRUE(peer.send(fd_block(0, 0, 0, 0)));
  const bool data = rig::wait_until([&] { return stream.read(b) == Status::kOk; });

  // Assert
  EXPECT_TRUE(bus_error);
  EXPECT_TRUE(off);
  EXPECT_EQ(read_while_off, Status::kBusOff);
  EXPECT_TRUE(recovered);
  EXPECT_TRUE(data);
  const auto st = stream.stats();
  EXPECT_EQ(st.bus_off, 1u);
  EXPECT_GE(st.error_frames, 3u);
  EXPECT_GE(st.recoveries, 1u);
}

TEST(RigSocketCan, SendsAHeartbeatThatCandumpSees) {
  RIG_SKIP_OUTSIDE();
  // Arrange: candump waits for one frame with the heartbeat id
  const std::string can = rig::env("DRIVETWIN_RIG_CAN", "vcan0");
  hal::MonotonicClock clock;
  hal::SocketCanConfig c = config(can, true);
  c.heartbeat_id = 0x170;
  hal::SocketCanCmsStream stream(c, clock);
  ASSERT_EQ(stream.configure(), Status::kOk);
  ASSERT_EQ(stream.activate(), Status::kOk);
  const std::string log = "/tmp/rig_socketcan_heartbeat.log";
  std::remove(log.c_str());
  rig::sh("timeout 20 candump -L -n 1 " + can + ",170:7FF > " + log + " &");
  std::this_thread::sleep_for(500ms);  // let candump bind

  // Act: counter 0x0102, status 0x0021; resend until candump has it
  const bool seen = rig::wait_until([&] {
    (void)stream.send_heartbeat(0x0102, 0x0021);
    return rig::read_text(log).find("170#") != std::string::npos;
  });

  // Assert: candump -L prints "(time) vcan0 170#02012100"
  ASSERT_TRUE(seen);
  EXPECT_NE(rig::read_text(log).find("170#02012100"), std::string::npos) << rig::read_text(log);
}

TEST(RigSocketCan, DecodesClassicFramesOnAClassicOnlyBus) {
  RIG_SKIP_OUTSIDE();
  // Arrange
  const std::string can = rig::env("DRIVETWIN_RIG_CAN_CLASSIC", "vcan1");
  hal::MonotonicClock clock;
  hal::SocketCanCmsStream stream(config(can, false), clock);
  ASSERT_EQ(stream.configure(), Status::kOk);
  ASSERT_EQ(stream.activate(), Status::kOk);

  // Act: seq 3, samples 1000, -1000, 0 on channel 0 (classic, 8 bytes)
  const std::string out = rig::sh("cansend " + can + " 180#0300E80318FC0000");
  hal::CmsBlock b;
  const bool got = rig::wait_until([&] { return stream.read(b) == Status::kOk; });

  // Assert
  ASSERT_TRUE(got) << out;
  EXPECT_EQ(b.sequence, 3);
  ASSERT_EQ(b.count, 3);
  EXPECT_FLOAT_EQ(b.samples[0], 1.0f);
  EXPECT_FLOAT_EQ(b.samples[1], -1.0f);
  EXPECT_FLOAT_EQ(b.samples[2], 0.0f);
}

TEST(RigSocketCan, FailsToConfigureOnAMissingInterface) {
  RIG_SKIP_OUTSIDE();
  hal::MonotonicClock clock;
  hal::SocketCanCmsStream stream(config("nocan7", true), clock);
  EXPECT_EQ(stream.configure(), Status::kIoError);
}

}  // namespace
