// haptic_udp_client: a reference device driver for phyxel's UdpDevice (docs/haptics.md). It
// replays a path as pose packets at a fixed rate (1 kHz by default) to HOST:PORT, logs every
// force packet that comes back and prints a one-line summary. A driver for a real device does
// the same with the device's pose, and applies the forces it receives.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "engine/scene/scene.h"
#include "engine/scene/tool_desc.h"
#include "engine/surgery/haptic_protocol.h"

namespace {

using phyxel::Vec3;
using Clock = std::chrono::steady_clock;
namespace haptic = phyxel::haptic;

constexpr const char* kHelp =
    R"(usage: haptic_udp_client --port PORT (--scene FILE | --from X,Y,Z --to X,Y,Z) [options]

Replays a tool path as phyxel haptic pose packets (docs/haptics.md) to HOST:PORT at a fixed
rate, logs the force packets that come back, and prints a one-line summary: poses sent,
forces received, round-trip median (from sending a pose to the first force echoing its seq).

path (one of):
  --scene FILE        the path of the scene's first tool with "control": "haptic"
  --from X,Y,Z --to X,Y,Z
                      a straight line (m), covered in --seconds
options:
  --port PORT         phyxel's UdpDevice port (required)
  --host ADDRESS      IPv4 address of phyxel (default 127.0.0.1)
  --seconds S         how long to send (default: the scene path's duration; 2 for a line)
  --axis X,Y,Z        the shaft axis for a line (default 0,0,1)
  --rate HZ           packets per second (default 1000)
  --log FILE          write every force received as CSV: t,seq,fx,fy,fz,status
                      (t: seconds since the first pose was sent)
  --help              this text
exit status: 0 when at least one force came back, 1 when none did, 2 on bad arguments.
)";

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

Vec3 parse_vec3(const std::string& flag, const std::string& text) {
  Vec3 v;
  const char* p = text.c_str();
  for (int i = 0; i < 3; ++i) {
    char* end = nullptr;
    v[i] = std::strtod(p, &end);
    const char want = i < 2 ? ',' : '\0';
    if (end == p || *end != want || !std::isfinite(v[i])) {
      throw UsageError(flag + " wants three numbers X,Y,Z, got '" + text + "'");
    }
    p = end + 1;
  }
  return v;
}

double parse_number(const std::string& flag, const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || !std::isfinite(v)) {
    throw UsageError(flag + " wants a number, got '" + text + "'");
  }
  return v;
}

struct Options {
  int port = -1;
  std::string host = "127.0.0.1";
  std::optional<std::string> scene, log;
  std::optional<Vec3> from, to;
  std::optional<double> seconds;
  Vec3 axis = Vec3::UnitZ();
  double rate = 1000;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw UsageError(flag + " needs a value");
      return argv[++i];
    };
    if (flag == "--port") {
      const double p = parse_number(flag, value());
      if (p < 1 || p > 65535 || p != std::floor(p)) throw UsageError("--port wants 1..65535");
      o.port = int(p);
    } else if (flag == "--host") {
      o.host = value();
    } else if (flag == "--scene") {
      o.scene = value();
    } else if (flag == "--from") {
      o.from = parse_vec3(flag, value());
    } else if (flag == "--to") {
      o.to = parse_vec3(flag, value());
    } else if (flag == "--axis") {
      o.axis = parse_vec3(flag, value());
      if (!(o.axis.norm() > 1e-9)) throw UsageError("--axis must not be zero");
    } else if (flag == "--seconds") {
      o.seconds = parse_number(flag, value());
      if (!(*o.seconds > 0)) throw UsageError("--seconds must be > 0");
    } else if (flag == "--rate") {
      o.rate = parse_number(flag, value());
      if (!(o.rate > 0 && o.rate <= 20000)) throw UsageError("--rate wants (0, 20000] Hz");
    } else if (flag == "--log") {
      o.log = value();
    } else {
      throw UsageError("unknown option '" + flag + "' (see --help)");
    }
  }
  if (o.port < 0) throw UsageError("--port is required (see --help)");
  if (o.scene && (o.from || o.to)) throw UsageError("give --scene or --from/--to, not both");
  if (!o.scene && !(o.from && o.to)) {
    throw UsageError("give a path: --scene FILE, or --from X,Y,Z --to X,Y,Z (see --help)");
  }
  return o;
}

// The path to replay and how long.
std::vector<phyxel::ToolKey> make_path(Options& o) {
  if (o.scene) {
    const phyxel::Scene scene = phyxel::load_scene(*o.scene);
    for (const phyxel::ToolDesc& tool : scene.tools) {
      if (tool.control == phyxel::ToolDesc::Control::Haptic && !tool.path.empty()) {
        if (!o.seconds) o.seconds = std::max(tool.path.back().t, 0.1);
        return tool.path;
      }
    }
    throw UsageError(*o.scene + ": no tool with \"control\": \"haptic\"; use --from/--to");
  }
  if (!o.seconds) o.seconds = 2;
  const Vec3 axis = o.axis.normalized();
  return {{0, *o.from, axis}, {*o.seconds, *o.to, axis}};
}

double since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// What went to the device and came back.
struct Exchange {
  std::vector<double> sent_at;  // by seq
  std::vector<bool> answered;
  std::vector<double> round_trips;
  uint64_t forces = 0, malformed = 0, send_errors = 0;
};

// The one line of figures; exit status 1 when no force came back.
int report(const Options& o, uint64_t count, Exchange& x) {
  double median = NAN;
  if (!x.round_trips.empty()) {
    std::sort(x.round_trips.begin(), x.round_trips.end());
    median = x.round_trips[x.round_trips.size() / 2];
  }
  char rtt[64] = "n/a";
  if (std::isfinite(median)) std::snprintf(rtt, sizeof rtt, "%.3f ms", 1e3 * median);
  std::printf(
      "haptic_udp_client: sent %llu poses to %s:%d in %.3f s (%llu send errors), received %llu "
      "forces (%llu malformed), round trip median %s over %zu answered poses\n",
      (unsigned long long)count, o.host.c_str(), o.port, *o.seconds,
      (unsigned long long)x.send_errors, (unsigned long long)x.forces,
      (unsigned long long)x.malformed, rtt, x.round_trips.size());
  if (x.forces == 0) {
    std::fprintf(stderr,
                 "haptic_udp_client: no force came back: is phyxel's UDP device listening on "
                 "%s:%d?\n",
                 o.host.c_str(), o.port);
    return 1;
  }
  return 0;
}

int run(Options o) {
  const std::vector<phyxel::ToolKey> path = make_path(o);
  sockaddr_in target{};
  target.sin_family = AF_INET;
  target.sin_port = htons(uint16_t(o.port));
  if (inet_pton(AF_INET, o.host.c_str(), &target.sin_addr) != 1) {
    throw UsageError("--host '" + o.host + "' is not an IPv4 address (e.g. 127.0.0.1)");
  }
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) throw std::runtime_error(std::string("socket: ") + std::strerror(errno));

  std::ofstream log;
  if (o.log) {
    log.open(*o.log);
    if (!log) throw std::runtime_error("cannot write the log '" + *o.log + "'");
    log << "t,seq,fx,fy,fz,status\n";
  }

  const auto period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / o.rate));
  const uint64_t count = uint64_t(std::ceil(*o.seconds * o.rate));
  Exchange x;

  // Drain every datagram waiting (from the target only).
  const auto receive = [&](Clock::time_point start) {
    std::array<uint8_t, haptic::kMaxMessageSize + 1> buffer;
    for (;;) {
      sockaddr_in from{};
      socklen_t len = sizeof from;
      const ssize_t n = ::recvfrom(fd, buffer.data(), buffer.size(), MSG_TRUNC,
                                   reinterpret_cast<sockaddr*>(&from), &len);
      if (n < 0) {
        if (errno == EINTR) continue;
        return;  // EAGAIN, or an ICMP refusal (nobody listening yet)
      }
      if (from.sin_port != target.sin_port || from.sin_addr.s_addr != target.sin_addr.s_addr) {
        continue;
      }
      haptic::ForceMessage f;
      if (size_t(n) > buffer.size() ||
          haptic::decode(std::span(buffer.data(), size_t(n)), f) != haptic::DecodeStatus::Ok) {
        ++x.malformed;
        continue;
      }
      const double t = since(start);
      ++x.forces;
      if (f.seq < x.sent_at.size() && !x.answered[f.seq]) {
        x.answered[f.seq] = true;
        x.round_trips.push_back(t - x.sent_at[f.seq]);
      }
      if (log.is_open()) {
        char line[160];
        std::snprintf(line, sizeof line, "%.6f,%u,%.9g,%.9g,%.9g,%u\n", t, f.seq, f.force.x() + 0.0,
                      f.force.y(), f.force.z(), f.status);
        log << line;
      }
    }
  };
  // Wait for replies until `until` (select: microsecond timeouts, POSIX).
  const auto wait_until = [&](Clock::time_point until, Clock::time_point start) {
    for (;;) {
      receive(start);
      const auto left = until - Clock::now();
      if (left <= Clock::duration::zero()) return;
      const auto us = std::chrono::duration_cast<std::chrono::microseconds>(left).count();
      timeval tv{static_cast<time_t>(us / 1000000), static_cast<suseconds_t>(us % 1000000)};
      fd_set set;
      FD_ZERO(&set);
      FD_SET(fd, &set);
      ::select(fd + 1, &set, nullptr, nullptr, &tv);
    }
  };

  const auto start = Clock::now();
  auto deadline = start;
  for (uint64_t seq = 0; seq < count; ++seq) {
    wait_until(deadline, start);
    const double t = since(start);
    const phyxel::ToolPose pose = phyxel::pose_at(path, t);
    haptic::PoseMessage m;
    m.seq = uint32_t(seq);
    m.device_time = t;
    m.position = pose.position;
    m.axis = pose.axis;
    const auto bytes = haptic::encode(m);
    x.sent_at.push_back(t);
    x.answered.push_back(false);
    if (::sendto(fd, bytes.data(), bytes.size(), 0, reinterpret_cast<const sockaddr*>(&target),
                 sizeof target) != ssize_t(bytes.size())) {
      ++x.send_errors;
    }
    deadline += period;
  }
  wait_until(Clock::now() + std::chrono::milliseconds(100), start);  // the last replies
  ::close(fd);

  return report(o, count, x);
}

}  // namespace

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h") {
      std::fputs(kHelp, stdout);
      return 0;
    }
  }
  try {
    return run(parse(argc, argv));
  } catch (const UsageError& e) {
    std::fprintf(stderr, "haptic_udp_client: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "haptic_udp_client: %s\n", e.what());
    return 1;
  }
}
