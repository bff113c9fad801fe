// UdpDevice on loopback against an in-test client socket, then against the reference client
// (tools/haptic_udp_client) with a running haptic loop. Ports: the device binds port 0 and
// the test asks which one it got, so parallel tests never collide.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <span>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "engine/surgery/haptic_loop.h"
#include "tests/support/support.h"

namespace phyxel {
namespace {

using phyxel::test::exit_status;

// A loopback UDP client with a receive timeout (so a lost packet fails the test, never hangs).
class Client {
 public:
  explicit Client(uint16_t port) {
    fd_ = ::socket(AF_INET, SOCK_DGRAM, 0);
    EXPECT_GE(fd_, 0);
    timeval tv{2, 0};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    to_.sin_family = AF_INET;
    to_.sin_port = htons(port);
    to_.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  }
  ~Client() { ::close(fd_); }
  void send(std::span<const uint8_t> bytes) {
    ASSERT_EQ(
        ::sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<sockaddr*>(&to_), sizeof to_),
        ssize_t(bytes.size()));
  }
  void send_pose(const haptic::PoseMessage& m) { send(haptic::encode(m)); }
  // The next force message; false on timeout or a malformed one.
  bool receive(haptic::ForceMessage& out) {
    std::array<uint8_t, 256> b;
    const ssize_t n = ::recv(fd_, b.data(), b.size(), 0);
    return n > 0 && haptic::decode(std::span(b.data(), size_t(n)), out) == haptic::DecodeStatus::Ok;
  }

 private:
  int fd_ = -1;
  sockaddr_in to_{};
};

// Reads the device until `done` holds (loopback delivers at once; the bound is for safety).
template <class Done>
HapticSample read_until(UdpDevice& device, double t, Done done) {
  HapticSample s;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  do {
    s = device.read(t);
    if (done()) break;
    std::this_thread::sleep_for(std::chrono::microseconds(50));
  } while (std::chrono::steady_clock::now() < give_up);
  return s;
}

haptic::PoseMessage pose(uint32_t seq) {
  haptic::PoseMessage m;
  m.seq = seq;
  m.device_time = 0.001 * seq;
  m.position = Vec3(0.001 * seq, -0.5 + 1e-7 * seq, 1.0 / (seq + 3));
  m.axis = Vec3(0, 0, 1);
  m.buttons = seq % 4;
  return m;
}

TEST(UdpDevice, PosesArriveIntactAndForcesComeBack) {
  UdpDevice device(0);
  ASSERT_NE(device.port(), 0);
  EXPECT_NE(device.name().find(std::to_string(device.port())), std::string::npos);
  Client client(device.port());
  EXPECT_FALSE(device.read(0).valid);  // nothing yet
  for (uint32_t seq = 1; seq <= 200; ++seq) {
    const double t = 0.001 * seq;
    const haptic::PoseMessage sent = pose(seq);
    client.send_pose(sent);
    const HapticSample s = read_until(device, t, [&] { return device.stats().poses == seq; });
    ASSERT_TRUE(s.valid) << "seq " << seq;
    EXPECT_EQ(s.pose.position, sent.position);
    EXPECT_EQ(s.pose.axis, sent.axis);
    EXPECT_EQ(s.buttons, sent.buttons);
    const Vec3 force(0.01 * seq, -1, 2);
    device.send(force, t, haptic::kStatusInContact);
    haptic::ForceMessage back;
    ASSERT_TRUE(client.receive(back)) << "seq " << seq;
    EXPECT_EQ(back.seq, seq);
    EXPECT_EQ(back.force, force);
    EXPECT_EQ(back.phyxel_time, t);
    EXPECT_EQ(back.status, haptic::kStatusInContact);
  }
  const UdpDeviceStats st = device.stats();
  EXPECT_EQ(st.poses, 200u);
  EXPECT_EQ(st.forces_sent, 200u);
  EXPECT_EQ(st.malformed, 0u);
  EXPECT_EQ(st.send_errors, 0u);
}

TEST(UdpDevice, KeepsTheNewestPoseAndAxisIsNormalized) {
  UdpDevice device(0);
  Client client(device.port());
  haptic::PoseMessage a = pose(10), b = pose(11), old = pose(5);
  b.axis = Vec3(0, 3, 4);
  client.send_pose(a);
  client.send_pose(b);
  client.send_pose(old);  // reordered: stale
  client.send_pose(b);    // duplicate: stale
  const HapticSample s = read_until(device, 0, [&] { return device.stats().datagrams == 4; });
  ASSERT_TRUE(s.valid);
  EXPECT_EQ(s.pose.position, b.position);
  EXPECT_LT((s.pose.axis - Vec3(0, 0.6, 0.8)).norm(), 1e-15);
  EXPECT_EQ(device.stats().poses, 2u);
  EXPECT_EQ(device.stats().stale, 2u);
  // A driver that restarts its count far back is taken.
  client.send_pose(pose(1u << 20));
  client.send_pose(pose(3));
  read_until(device, 0, [&] { return device.stats().datagrams == 6; });
  EXPECT_EQ(device.stats().poses, 4u);
  // Silent past the timeout: invalid, nothing claimed.
  EXPECT_FALSE(device.read(1.0).valid);
}

// Who may drive the tool: the first sender is pinned; a second socket's poses are dropped and
// counted while the first keeps sending, and taken only once it has been silent past the
// timeout; forces go to the pinned sender.
TEST(UdpDevice, TheFirstSenderIsPinnedAndAnotherIsIgnored) {
  UdpDevice device(0, "127.0.0.1", 0.25);
  Client first(device.port()), intruder(device.port());
  first.send_pose(pose(1));
  HapticSample s = read_until(device, 0.0, [&] { return device.stats().poses == 1; });
  ASSERT_TRUE(s.valid);
  for (uint32_t k = 0; k < 20; ++k) {
    intruder.send_pose(pose(1000 + k));
    const double t = 0.01 * k;
    first.send_pose(pose(2 + k));
    s = read_until(device, t, [&] { return device.stats().datagrams == 3 + 2 * k; });
    ASSERT_TRUE(s.valid);
    EXPECT_EQ(s.pose.position, pose(2 + k).position) << k;  // never the intruder's
  }
  UdpDeviceStats st = device.stats();
  EXPECT_EQ(st.foreign, 20u);
  EXPECT_EQ(st.poses, 21u);
  EXPECT_EQ(st.pins, 1u);
  device.send(Vec3(1, 2, 3), 0.2);
  haptic::ForceMessage back;
  ASSERT_TRUE(first.receive(back));
  EXPECT_EQ(back.seq, 21u);
  // The first silent past the timeout: the next sender is pinned.
  intruder.send_pose(pose(5000));
  s = read_until(device, 0.19 + 0.3, [&] { return device.stats().datagrams == 42; });
  ASSERT_TRUE(s.valid);
  EXPECT_EQ(s.pose.position, pose(5000).position);
  st = device.stats();
  EXPECT_EQ(st.pins, 2u);
  EXPECT_EQ(st.foreign, 20u);
}

// A device that allows one peer address drops everyone else, loopback included.
TEST(UdpDevice, OnlyTheAllowedPeerDrives) {
  UdpDevice device(0, "127.0.0.1", 0.25, "192.0.2.7");
  Client client(device.port());
  client.send_pose(pose(1));
  const HapticSample s = read_until(device, 0.0, [&] { return device.stats().datagrams == 1; });
  EXPECT_FALSE(s.valid);
  EXPECT_EQ(device.stats().refused, 1u);
  EXPECT_EQ(device.stats().poses, 0u);
  try {
    UdpDevice bad(0, "127.0.0.1", 0.25, "nowhere");
    ADD_FAILURE() << "took a peer that is not an address";
  } catch (const HapticError& e) {
    EXPECT_NE(std::string(e.what()).find("'nowhere'"), std::string::npos) << e.what();
  }
}

TEST(UdpDevice, MalformedDatagramsAreDroppedAndCounted) {
  UdpDevice device(0);
  Client client(device.port());
  const auto good = haptic::encode(pose(1));
  const auto send_modified = [&](auto modify) {
    std::vector<uint8_t> b(good.begin(), good.end());
    modify(b);
    client.send(b);
  };
  send_modified([](auto& b) { b.resize(71); });         // size: short
  send_modified([](auto& b) { b.resize(200, 0); });     // size: long
  send_modified([](auto& b) { b[1] = 'Y'; });           // magic
  send_modified([](auto& b) { b[4] = 7; });             // version
  send_modified([](auto& b) { b[6] = 2; });             // type: a force id
  client.send(haptic::encode(haptic::ForceMessage{}));  // type: a force message (48 bytes)
  haptic::PoseMessage nan = pose(2);
  nan.position.x() = std::numeric_limits<double>::quiet_NaN();
  client.send_pose(nan);  // non-finite
  haptic::PoseMessage zero = pose(3);
  zero.axis = Vec3::Zero();
  client.send_pose(zero);  // zero axis
  const HapticSample s = read_until(device, 0, [&] { return device.stats().datagrams == 8; });
  EXPECT_FALSE(s.valid);
  const UdpDeviceStats st = device.stats();
  EXPECT_EQ(st.malformed, 8u);
  EXPECT_EQ(st.poses, 0u);
  using haptic::DecodeStatus;
  EXPECT_EQ(st.malformed_by[size_t(DecodeStatus::Size)], 2u);
  EXPECT_EQ(st.malformed_by[size_t(DecodeStatus::Magic)], 1u);
  EXPECT_EQ(st.malformed_by[size_t(DecodeStatus::Version)], 1u);
  EXPECT_EQ(st.malformed_by[size_t(DecodeStatus::Type)], 2u);
  EXPECT_EQ(st.malformed_by[size_t(DecodeStatus::NonFinite)], 1u);
  EXPECT_EQ(st.malformed_by[size_t(DecodeStatus::ZeroAxis)], 1u);
  // Before any valid pose there is no one to answer.
  device.send(Vec3(1, 2, 3), 0);
  EXPECT_EQ(device.stats().forces_sent, 0u);
  // A good pose after the garbage is taken.
  client.send(good);
  EXPECT_TRUE(read_until(device, 0, [&] { return device.stats().poses == 1; }).valid);
}

TEST(UdpDevice, ClearErrorsForAPortInUseAndABadAddress) {
  UdpDevice first(0);
  try {
    UdpDevice second(first.port());
    FAIL() << "binding a port in use must throw";
  } catch (const HapticError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("port " + std::to_string(first.port())), std::string::npos) << what;
    EXPECT_NE(what.find("in use"), std::string::npos) << what;
    EXPECT_NE(what.find("another port"), std::string::npos) << what;
  }
  try {
    UdpDevice bad(0, "localhost:9");
    FAIL() << "a bad address must throw";
  } catch (const HapticError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'localhost:9'"), std::string::npos) << what;
    EXPECT_NE(what.find("127.0.0.1"), std::string::npos) << what;
  }
  EXPECT_THROW(UdpDevice(0, "10.255.255.254"), HapticError);  // not this machine's
}

// Runs a command, returns its exit status and stdout.
int run_command(const std::string& command, std::string& out) {
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return -1;
  char buffer[512];
  while (std::fgets(buffer, sizeof buffer, pipe)) out += buffer;
  const int status = ::pclose(pipe);
  return exit_status(status);
}

std::filesystem::path out_dir() {
  const char* env = std::getenv("PHYXEL_TEST_OUT");
  std::filesystem::path dir = env ? env : PHYXEL_BINARY_DIR "/test-out";
  dir /= "haptics";
  std::filesystem::create_directories(dir);
  return dir;
}

const std::string kClient = PHYXEL_BINARY_DIR "/tools/haptic_udp_client";

TEST(UdpDevice, TheReferenceClientDrivesAHapticLoop) {
  auto device = std::make_shared<UdpDevice>(0);
  HapticLoop loop(device, CouplingSettings{}, ToolPose{});
  loop.publish(HapticSnapshot{0, HapticLoop::clock(), Vec3(0, 0, 0.5), 2});
  loop.start();
  const std::filesystem::path log = out_dir() / "client_forces.csv";
  std::filesystem::remove(log);
  std::string out;
  const int rc = run_command(kClient + " --port " + std::to_string(device->port()) +
                                 " --from 0,0,0 --to 0,0,0.01 --seconds 0.3 --log " + log.string(),
                             out);
  loop.stop();
  EXPECT_EQ(rc, 0) << out;
  EXPECT_NE(out.find("sent 300 poses"), std::string::npos) << out;
  EXPECT_NE(out.find("round trip median"), std::string::npos) << out;
  const UdpDeviceStats st = device->stats();
  EXPECT_GT(st.poses, 0u);
  EXPECT_EQ(st.malformed, 0u);
  EXPECT_GT(st.forces_sent, 0u);
  // The log: a header and one row per force received, six fields, the contact flag set.
  std::ifstream in(log);
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line, "t,seq,fx,fy,fz,status");
  int rows = 0;
  while (std::getline(in, line)) {
    ++rows;
    std::stringstream fields(line);
    std::string field;
    int n = 0;
    while (std::getline(fields, field, ',')) ++n;
    EXPECT_EQ(n, 6) << line;
    EXPECT_EQ(field, "1") << line;  // kStatusInContact
  }
  EXPECT_GT(rows, 0);
  // The tool followed the replayed line (the last pose was at z = 0.01 m).
  EXPECT_GT(loop.state().device.position.z(), 0.0);
}

TEST(UdpDevice, TheReferenceClientExplainsItsArguments) {
  std::string out;
  EXPECT_EQ(run_command(kClient + " --help", out), 0);
  EXPECT_NE(out.find("--from X,Y,Z"), std::string::npos);
  out.clear();
  EXPECT_EQ(run_command(kClient + " --from 0,0 --to 1,1,1 --port 9 2>&1", out), 2);
  EXPECT_NE(out.find("three numbers"), std::string::npos) << out;
  out.clear();
  // A scene without a haptic tool names the problem.
  EXPECT_EQ(
      run_command(kClient + " --port 9 --scene " PHYXEL_SOURCE_DIR "/scenes/beam.json 2>&1", out),
      2);
  EXPECT_NE(out.find("no tool with"), std::string::npos) << out;
}

}  // namespace
}  // namespace phyxel
