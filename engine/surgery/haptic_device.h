// Haptic devices (docs/haptics.md): where a haptic tool's pose comes from and where the force
// on the hand goes. The haptic loop (engine/surgery/haptic_loop.h) calls read() and send() once
// per tick, from its own thread, so an implementation must return at once (no blocking I/O).
//
//   ScriptedDevice    a path of keyframes replayed in time (headless runs, tests)
//   SharedPoseDevice  a pose set by another thread (the viewer's mouse)
//   UdpDevice         pose packets from an external driver over UDP, force packets back
//                     (engine/surgery/haptic_protocol.h)
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/geometry/tool.h"
#include "engine/surgery/haptic_protocol.h"

namespace phyxel {

// Thrown when a device cannot be opened (a port in use, a bad address); what() names the
// device and says what to do.
struct HapticError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// One reading of a device. `valid` is false while the device has no pose to give (no packet
// yet, or the driver went silent); the pose's axis is unit when valid.
struct HapticSample {
  ToolPose pose;
  bool valid = false;
  uint32_t buttons = 0;
};

class HapticDevice {
 public:
  virtual ~HapticDevice() = default;
  virtual std::string name() const = 0;
  // The device's pose at `wall_time` (s, the haptic loop's clock: HapticLoop::clock()).
  virtual HapticSample read(double wall_time) = 0;
  // The force to apply to the hand (N) at `wall_time`, with the haptic::kStatus* flags.
  virtual void send(const Vec3& force_on_hand, double wall_time, uint32_t status = 0) = 0;
};

// Replays a path (pose_at): the pose at wall time w is pose_at(path, w - w0), w0 the wall time
// of the first read() (or the one given). The last force sent is kept.
class ScriptedDevice : public HapticDevice {
 public:
  explicit ScriptedDevice(std::vector<ToolKey> path, std::optional<double> start_time = {});
  std::string name() const override { return "scripted"; }
  HapticSample read(double wall_time) override;
  void send(const Vec3& force_on_hand, double wall_time, uint32_t status = 0) override;

  Vec3 last_force() const;
  uint32_t last_status() const;
  uint64_t sends() const;

 private:
  std::vector<ToolKey> path_;
  std::optional<double> start_;
  mutable std::mutex mutex_;
  Vec3 force_ = Vec3::Zero();
  uint32_t status_ = 0;
  uint64_t sends_ = 0;
};

// A pose set from another thread (set_pose, e.g. the viewer's mouse), read by the haptic loop.
// Invalid until the first set_pose() and after clear(). The last force sent is readable (for
// display). A small mutex guards a few dozen bytes: neither side holds it for longer than a
// copy.
class SharedPoseDevice : public HapticDevice {
 public:
  std::string name() const override { return "shared pose"; }
  HapticSample read(double wall_time) override;
  void send(const Vec3& force_on_hand, double wall_time, uint32_t status = 0) override;

  void set_pose(const ToolPose& pose, uint32_t buttons = 0);  // axis normalized; non-zero
  void clear();
  Vec3 last_force() const;
  uint32_t last_status() const;

 private:
  mutable std::mutex mutex_;
  HapticSample sample_;
  Vec3 force_ = Vec3::Zero();
  uint32_t status_ = 0;
};

// Counters of a UdpDevice.
struct UdpDeviceStats {
  uint64_t datagrams = 0;  // received, of any kind
  uint64_t poses = 0;      // valid pose messages taken
  uint64_t stale = 0;      // valid poses older (by seq) than the newest, dropped
  uint64_t malformed = 0;  // refused by decode(), dropped
  std::array<uint64_t, haptic::kDecodeStatusCount> malformed_by{};  // by DecodeStatus
  uint64_t foreign = 0;      // valid poses of another sender while one is pinned, dropped
  uint64_t refused = 0;      // datagrams from a sender that is not allowed (peer), dropped
  uint64_t pins = 0;         // senders pinned (the first, and one after each silence)
  uint64_t forces_sent = 0;  // force messages sent
  uint64_t send_errors = 0;  // sendto() failures (the socket buffer full, unreachable)
};

// A non-blocking UDP socket bound to `bind_address`:`port` (port 0: the system picks one, see
// port()). read() drains every datagram waiting, keeps the newest valid pose (by seq: a pose
// whose seq equals the newest or is up to 1024 behind it is stale; a larger jump back is taken,
// as a restarted driver) and drops malformed ones, counting them. Who may drive the tool: the
// first sender of a valid pose is pinned; poses of any other sender are dropped and counted
// (`foreign`) until the pinned one has been silent past the timeout, when the next sender is
// pinned. Senders must be on loopback (127.0.0.0/8) unless `peer` names the one IPv4 address
// allowed; others are dropped and counted (`refused`). The pose is
// valid until no pose arrived for `timeout` seconds. send() answers the sender of the newest
// pose with a force message echoing that pose's seq; nothing is sent before a pose arrived.
class UdpDevice : public HapticDevice {
 public:
  explicit UdpDevice(uint16_t port, const std::string& bind_address = "127.0.0.1",
                     double timeout = 0.25, const std::string& peer = "");
  ~UdpDevice() override;
  UdpDevice(const UdpDevice&) = delete;
  UdpDevice& operator=(const UdpDevice&) = delete;

  std::string name() const override;
  HapticSample read(double wall_time) override;
  void send(const Vec3& force_on_hand, double wall_time, uint32_t status = 0) override;

  uint16_t port() const { return port_; }
  UdpDeviceStats stats() const;

 private:
  int fd_ = -1;
  uint16_t port_ = 0;
  std::string address_;
  double timeout_;
  uint32_t peer_ = 0;         // the allowed sender (network order), 0: loopback only
  mutable std::mutex mutex_;  // guards the state below: read/send from the loop, stats()
  UdpDeviceStats stats_;
  bool have_pose_ = false;
  double last_arrival_ = 0;  // wall time of the read() that took the newest pose
  haptic::PoseMessage pose_;
  std::array<uint8_t, 16> sender_{};  // sockaddr_in of the newest pose's sender
  uint32_t sender_len_ = 0;
};

}  // namespace phyxel
