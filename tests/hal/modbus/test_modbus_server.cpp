// ModbusResultsServer read by independent clients: Debian's mbpoll (a separate
// program), a libmodbus master, and raw sockets sending garbage and floods.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "../no_alloc.hpp"
#include "hal/modbus_results_server.hpp"
#include "modbus_test_util.hpp"

namespace {

using namespace std::chrono_literals;
using hal::Status;
using modbus_test::wait_until;

std::string run(const std::string& cmd) {
  std::string out;
  std::unique_ptr<FILE, int (*)(FILE*)> p(::popen((cmd + " 2>&1").c_str(), "r"), ::pclose);
  if (!p) return out;
  char buf[512];
  while (std::fgets(buf, sizeof buf, p.get())) out += buf;
  return out;
}

bool have_mbpoll() { return run("command -v mbpoll").find("mbpoll") != std::string::npos; }

/// Values mbpoll printed as "[ref]: value" lines (no std::regex: GCC 12 warns
/// inside <regex> under -fsanitize, and warnings are errors).
std::vector<std::string> mbpoll_values(const std::string& out) {
  std::vector<std::string> v;
  std::istringstream in(out);
  std::string line;
  while (std::getline(in, line)) {
    const auto close = line.find("]:");
    if (line.empty() || line[0] != '[' || close == std::string::npos) continue;
    std::istringstream rest(line.substr(close + 2));
    std::string value;
    if (rest >> value) v.push_back(value);
  }
  return v;
}

// hal serves an image without knowing what it means: the tests give it a layout of their
// own (that of the application's header, so the numbers read like the twin's).
constexpr std::uint16_t kTestRegisters = 166;
constexpr std::uint16_t kTestCommandStart = 150;
constexpr std::uint16_t kTestCommandCount = 16;
constexpr std::uint16_t kVersionAddr = 0;   // uint16
constexpr std::uint16_t kStatusAddr = 1;    // uint16
constexpr std::uint16_t kSequenceAddr = 4;  // uint32
constexpr std::uint16_t kTorqueAddr = 8;    // float32, then speed at 10, wind at 12
constexpr std::uint16_t kTestVersion = 1;

hal::RegisterImage paper_point_image(std::uint32_t sequence = 77) {
  using hal::RegisterType;
  constexpr auto kHigh = hal::WordOrder::kHighWordFirst;
  hal::RegisterImage img;
  img.count = kTestRegisters;
  EXPECT_TRUE(hal::put_register(img, kVersionAddr, RegisterType::kUInt16, kHigh, kTestVersion));
  EXPECT_TRUE(hal::put_register(img, kStatusAddr, RegisterType::kUInt16, kHigh, 0x21));  // 33
  EXPECT_TRUE(hal::put_register(img, kSequenceAddr, RegisterType::kUInt32, kHigh, sequence));
  EXPECT_TRUE(hal::put_register(img, kTorqueAddr, RegisterType::kFloat32, kHigh, 361747.0));
  EXPECT_TRUE(hal::put_register(img, kTorqueAddr + 2, RegisterType::kFloat32, kHigh, 8.33));
  EXPECT_TRUE(hal::put_register(img, kTorqueAddr + 4, RegisterType::kFloat32, kHigh, 6.75));
  // Words in the command block are the clients', never served from the image.
  img.words[kTestCommandStart] = 0xDEAD;
  return img;
}

hal::ModbusServerConfig test_config() {
  hal::ModbusServerConfig c;
  c.register_count = kTestRegisters;
  c.command_start = kTestCommandStart;
  c.command_count = kTestCommandCount;
  return c;
}

class ResultsServer : public ::testing::Test {
 protected:
  void start(hal::ModbusServerConfig c = test_config()) {
    c.port = 0;
    server_ = std::make_unique<hal::ModbusResultsServer>(c);
    ASSERT_EQ(server_->configure(), Status::kOk);
    ASSERT_EQ(server_->activate(), Status::kOk);
    ASSERT_EQ(server_->publish(paper_point_image()), Status::kOk);
    port_ = server_->bound_port();
  }
  modbus_t* connect_master() {
    modbus_t* m = modbus_new_tcp("127.0.0.1", port_);
    modbus_set_response_timeout(m, 2, 0);
    if (modbus_connect(m) != 0) {
      modbus_free(m);
      return nullptr;
    }
    return m;
  }
  int raw_connect() {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in sa{};
    sa.sin_family = AF_INET;
    sa.sin_port = htons(port_);
    sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd, reinterpret_cast<sockaddr*>(&sa), sizeof sa) != 0) {
      ::close(fd);
      return -1;
    }
    return fd;
  }
  std::string mbpoll(const std::string& args) {
    return run("mbpoll -m tcp -a 1 -1 -o 2 -p " + std::to_string(port_) + " " + args +
               " 127.0.0.1");
  }

  std::unique_ptr<hal::ModbusResultsServer> server_;
  std::uint16_t port_ = 0;
};

TEST_F(ResultsServer, ServesThePublishedImageToMbpoll) {
  // Arrange
  ASSERT_TRUE(have_mbpoll()) << "mbpoll missing: run tools/setup.sh";
  start();

  // Act: PDU addresses (-0): version and status words; float torque and speed (high word first, -B)
  const auto words = mbpoll_values(mbpoll("-0 -r 0 -c 2 -t 4"));
  const auto floats = mbpoll_values(mbpoll("-0 -r 8 -c 3 -t 4:float -B"));
  const auto input_floats = mbpoll_values(mbpoll("-0 -r 8 -c 1 -t 3:float -B"));

  // Assert
  ASSERT_EQ(words.size(), 2u);
  EXPECT_EQ(words[0], "1");   // version word
  EXPECT_EQ(words[1], "33");  // running | calibrated
  ASSERT_EQ(floats.size(), 3u);
  EXPECT_EQ(floats[0], "361747");
  EXPECT_NEAR(std::stod(floats[1]), 8.33, 1e-5);
  EXPECT_NEAR(std::stod(floats[2]), 6.75, 1e-6);
  ASSERT_EQ(input_floats.size(), 1u);
  EXPECT_EQ(input_floats[0], "361747");
}

TEST_F(ResultsServer, AnswersIllegalAddressesAndFunctionsWithModbusExceptions) {
  // Arrange
  start();
  modbus_t* m = connect_master();
  ASSERT_NE(m, nullptr);
  std::uint16_t regs[8];
  std::uint8_t bits[8];

  // Act / Assert: beyond the image → exception 02 (illegal data address)
  EXPECT_EQ(modbus_read_registers(m, kTestRegisters - 1, 2, regs), -1);
  EXPECT_EQ(errno, EMBXILADD);
  // coils → exception 01 (illegal function)
  EXPECT_EQ(modbus_read_bits(m, 0, 1, bits), -1);
  EXPECT_EQ(errno, EMBXILFUN);
  // a write to a read-only server → exception 01
  EXPECT_EQ(modbus_write_register(m, 8, 1), -1);
  EXPECT_EQ(errno, EMBXILFUN);
  // the connection is still good after the exceptions
  EXPECT_EQ(modbus_read_registers(m, 0, 1, regs), 1);
  EXPECT_EQ(regs[0], kTestVersion);
  EXPECT_GE(server_->stats().exceptions, 3u);
  modbus_close(m);
  modbus_free(m);
}

TEST_F(ResultsServer, MbpollSeesTheExceptionForAnAddressOutsideTheMap) {
  // Arrange
  ASSERT_TRUE(have_mbpoll()) << "mbpoll missing: run tools/setup.sh";
  start();

  // Act
  const std::string out = mbpoll("-0 -r 1000 -c 1 -t 4");

  // Assert
  EXPECT_NE(out.find("Illegal data address"), std::string::npos) << out;
}

TEST_F(ResultsServer, AcceptsWritesOnlyToTheRegistersListedWritable) {
  // Arrange: command register 150 writable, 151 not
  hal::ModbusServerConfig c = test_config();
  c.writable = {kTestCommandStart};
  start(c);
  modbus_t* m = connect_master();
  ASSERT_NE(m, nullptr);

  // Act
  std::uint16_t before = 0;
  const int read_before = modbus_read_registers(m, kTestCommandStart, 1, &before);
  const int ok = modbus_write_register(m, kTestCommandStart, 0xBEEF);
  const int refused = modbus_write_register(m, kTestCommandStart + 1, 1);
  const int refused_errno = errno;
  const int refused_results = modbus_write_register(m, kTorqueAddr, 1);
  ASSERT_EQ(server_->publish(paper_point_image()), Status::kOk);  // image has 0xDEAD there
  std::uint16_t after = 0;
  const int read_after = modbus_read_registers(m, kTestCommandStart, 1, &after);

  // Assert
  EXPECT_EQ(ok, 1);
  EXPECT_EQ(refused, -1);
  EXPECT_EQ(refused_errno, EMBXILADD);
  EXPECT_EQ(refused_results, -1);
  EXPECT_EQ(server_->commands().values[0], 0xBEEF);
  EXPECT_EQ(server_->commands().writes, 1u);
  // The command block shows what clients wrote, never what the image holds there.
  EXPECT_EQ(read_before, 1);
  EXPECT_EQ(before, 0);
  EXPECT_EQ(read_after, 1);
  EXPECT_EQ(after, 0xBEEF);
  modbus_close(m);
  modbus_free(m);
}

TEST_F(ResultsServer, DropsAMalformedClientWithoutDisturbingAnother) {
  // Arrange: a good client connected first
  start();
  modbus_t* good = connect_master();
  ASSERT_NE(good, nullptr);
  const int bad = raw_connect();
  const int slow = raw_connect();
  ASSERT_GE(bad, 0);
  ASSERT_GE(slow, 0);

  // Act: protocol id 0x1234 (must be 0), and half a frame that never completes
  const std::uint8_t garbage[] = {0x00, 0x01, 0x12, 0x34, 0x00, 0x06,
                                  0x01, 0x03, 0x00, 0x00, 0x00, 0x01};
  const std::uint8_t half[] = {0x00, 0x02, 0x00, 0x00, 0x00, 0x06, 0x01};
  ASSERT_EQ(::send(bad, garbage, sizeof garbage, 0), static_cast<ssize_t>(sizeof garbage));
  ASSERT_EQ(::send(slow, half, sizeof half, 0), static_cast<ssize_t>(sizeof half));
  char c;
  const ssize_t closed = ::recv(bad, &c, 1, 0);  // server closes the malformed connection
  std::uint16_t reg = 0;
  const int read = modbus_read_registers(good, 0, 1, &reg);

  // Assert
  EXPECT_EQ(closed, 0);
  EXPECT_EQ(read, 1);
  EXPECT_EQ(reg, kTestVersion);
  EXPECT_EQ(server_->stats().malformed, 1u);
  ::close(bad);
  ::close(slow);
  modbus_close(good);
  modbus_free(good);
}

TEST_F(ResultsServer, StaysAvailableThroughAFloodOfConnectionsBeyondItsLimit) {
  // Arrange: at most 2 clients; one legitimate client holds a connection
  hal::ModbusServerConfig c = test_config();
  c.max_connections = 2;
  start(c);
  modbus_t* good = connect_master();
  ASSERT_NE(good, nullptr);

  // Act: 40 connections at once
  std::vector<int> flood;
  for (int i = 0; i < 40; ++i) flood.push_back(raw_connect());
  ASSERT_TRUE(wait_until([&] { return server_->stats().rejected >= 39; }));
  std::uint16_t reg = 0;
  const int during = modbus_read_registers(good, 1, 1, &reg);
  for (int fd : flood)
    if (fd >= 0) ::close(fd);
  ASSERT_TRUE(wait_until([&] { return server_->stats().open_connections == 1; }));
  modbus_t* later = connect_master();
  std::uint16_t reg2 = 0;
  const int after = later ? modbus_read_registers(later, 1, 1, &reg2) : -1;

  // Assert: the held connection was served during the flood, a new one after it
  EXPECT_EQ(during, 1);
  EXPECT_EQ(reg, 0x0021);
  EXPECT_EQ(after, 1);
  EXPECT_LE(server_->stats().open_connections, 2);
  if (later) {
    modbus_close(later);
    modbus_free(later);
  }
  modbus_close(good);
  modbus_free(good);
}

TEST_F(ResultsServer, DisconnectsClientsNotOnTheAllowList) {
  // Arrange: only 127.0.0.2 may connect; the test connects from 127.0.0.1
  hal::ModbusServerConfig c = test_config();
  c.allow = {"127.0.0.2"};
  start(c);

  // Act
  const int fd = raw_connect();
  char ch;
  const ssize_t r = fd >= 0 ? ::recv(fd, &ch, 1, 0) : -1;

  // Assert: connection closed by the server without an answer
  EXPECT_EQ(r, 0);
  EXPECT_TRUE(wait_until([&] { return server_->stats().rejected == 1; }));
  if (fd >= 0) ::close(fd);
}

TEST_F(ResultsServer, ServesNewResultsAsSoonAsTheyArePublished) {
  // Arrange
  start();
  modbus_t* m = connect_master();
  ASSERT_NE(m, nullptr);
  const hal::RegisterImage r = paper_point_image(0x12345678);

  // Act
  ASSERT_EQ(server_->publish(r), Status::kOk);
  std::uint16_t regs[2] = {};
  const int n = modbus_read_input_registers(m, kSequenceAddr, 2, regs);

  // Assert
  EXPECT_EQ(n, 2);
  EXPECT_EQ(regs[0], 0x1234);
  EXPECT_EQ(regs[1], 0x5678);
  modbus_close(m);
  modbus_free(m);
}

TEST_F(ResultsServer, PublishOnTheLoopThreadAllocatesNothing) {
  // Arrange
  start();
  hal::RegisterImage r = paper_point_image();

  // Act
  no_alloc::Scope scope;
  for (std::uint32_t i = 0; i < 1000; ++i) {
    r.words[kSequenceAddr + 1] = static_cast<std::uint16_t>(i);
    (void)server_->publish(r);
  }

  // Assert
  EXPECT_EQ(scope.allocations(), 0u);
}

TEST(ResultsServerConfig, RejectsWritableRegistersOutsideTheCommandBlock) {
  hal::ModbusServerConfig c = test_config();
  c.port = 0;
  c.writable = {kTorqueAddr};
  hal::ModbusResultsServer s(c);
  EXPECT_EQ(s.configure(), Status::kInvalidConfig);
}

TEST(ResultsServerConfig, RejectsAnImageSizeOrCommandBlockThatDoesNotFit) {
  auto refused = [](auto change) {
    hal::ModbusServerConfig c = test_config();
    c.port = 0;
    change(c);
    hal::ModbusResultsServer s(c);
    return s.configure() == Status::kInvalidConfig;
  };
  EXPECT_TRUE(refused([](hal::ModbusServerConfig& c) { c.register_count = 0; }));
  EXPECT_TRUE(refused([](hal::ModbusServerConfig& c) {
    c.register_count = static_cast<std::uint16_t>(hal::kMaxImageRegisters + 1);
  }));
  EXPECT_TRUE(refused([](hal::ModbusServerConfig& c) { c.command_start = kTestRegisters - 4; }));
  EXPECT_TRUE(refused([](hal::ModbusServerConfig& c) {
    c.command_count = static_cast<std::uint16_t>(hal::kMaxCommandRegisters + 1);
  }));
}

TEST(ResultsServerConfig, TheServerThreadRunsWithTheAttributesItWasGiven) {
  // Arrange
  hal::ModbusServerConfig c = test_config();
  c.port = 0;
  c.thread = {"dt-test-srv", hal::SchedPolicy::kBatch, 4, -1, 128 * 1024};
  hal::ModbusResultsServer s(c);
  // Act
  ASSERT_EQ(s.configure(), Status::kOk);
  // Assert: a thread of this process carries the name (the OS's view, /proc).
  bool found = false;
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task")) {
    std::ifstream comm(task.path() / "comm");
    std::string name;
    std::getline(comm, name);
    found |= name == "dt-test-srv";
  }
  EXPECT_TRUE(found);
  EXPECT_TRUE(s.thread_report().started);
  EXPECT_TRUE(s.thread_report().policy_applied) << s.thread_report().warning;
  EXPECT_GE(s.thread_report().stack_bytes, 128u * 1024u);  // sanitizers enlarge stacks
}

}  // namespace
