#include "engine/surgery/haptic_device.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <span>

namespace phyxel {

// ---- ScriptedDevice ----

ScriptedDevice::ScriptedDevice(std::vector<ToolKey> path, std::optional<double> start_time)
    : path_(std::move(path)), start_(start_time) {
  if (path_.empty()) throw HapticError("scripted haptic device: the path has no keyframe");
}

HapticSample ScriptedDevice::read(double wall_time) {
  if (!start_) start_ = wall_time;
  HapticSample sample;
  sample.pose = pose_at(path_, wall_time - *start_);
  sample.pose.axis.normalize();
  sample.valid = true;
  return sample;
}

void ScriptedDevice::send(const Vec3& force_on_hand, double, uint32_t status) {
  std::lock_guard lock(mutex_);
  force_ = force_on_hand;
  status_ = status;
  ++sends_;
}

Vec3 ScriptedDevice::last_force() const {
  std::lock_guard lock(mutex_);
  return force_;
}

uint32_t ScriptedDevice::last_status() const {
  std::lock_guard lock(mutex_);
  return status_;
}

uint64_t ScriptedDevice::sends() const {
  std::lock_guard lock(mutex_);
  return sends_;
}

// ---- SharedPoseDevice ----

HapticSample SharedPoseDevice::read(double) {
  std::lock_guard lock(mutex_);
  return sample_;
}

void SharedPoseDevice::send(const Vec3& force_on_hand, double, uint32_t status) {
  std::lock_guard lock(mutex_);
  force_ = force_on_hand;
  status_ = status;
}

void SharedPoseDevice::set_pose(const ToolPose& pose, uint32_t buttons) {
  const double n = pose.axis.norm();
  if (!pose.position.allFinite() || !pose.axis.allFinite() || !(n >= 1e-9)) {
    throw HapticError(
        "shared-pose haptic device: set_pose needs a finite position and a "
        "finite non-zero axis");
  }
  std::lock_guard lock(mutex_);
  sample_.pose = {pose.position, pose.axis / n};
  sample_.valid = true;
  sample_.buttons = buttons;
}

void SharedPoseDevice::clear() {
  std::lock_guard lock(mutex_);
  sample_.valid = false;
}

Vec3 SharedPoseDevice::last_force() const {
  std::lock_guard lock(mutex_);
  return force_;
}

uint32_t SharedPoseDevice::last_status() const {
  std::lock_guard lock(mutex_);
  return status_;
}

// ---- UdpDevice ----

namespace {

std::string where(const std::string& address, uint16_t port) {
  return address + ":" + std::to_string(port);
}

}  // namespace

UdpDevice::UdpDevice(uint16_t port, const std::string& bind_address, double timeout,
                     const std::string& peer)
    : address_(bind_address), timeout_(timeout) {
  in_addr allowed{};
  if (!peer.empty() && inet_pton(AF_INET, peer.c_str(), &allowed) != 1)
    throw HapticError("haptic UDP device: peer address '" + peer +
                      "' is not an IPv4 address; use the dotted quad of the driver's machine");
  peer_ = allowed.s_addr;
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(port);
  if (inet_pton(AF_INET, bind_address.c_str(), &addr.sin_addr) != 1) {
    throw HapticError("haptic UDP device: bind address '" + bind_address +
                      "' is not an IPv4 address; use a dotted quad such as 127.0.0.1 (this "
                      "machine only) or 0.0.0.0 (every interface)");
  }
  if (!(timeout > 0)) throw HapticError("haptic UDP device: the pose timeout must be > 0 s");
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) {
    throw HapticError(std::string("haptic UDP device: cannot create a UDP socket: ") +
                      std::strerror(errno));
  }
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    const int err = errno;
    ::close(fd_);
    fd_ = -1;
    const std::string at = where(bind_address, port);
    if (err == EADDRINUSE) {
      throw HapticError("haptic UDP device: port " + std::to_string(port) + " on " + bind_address +
                        " is in use (another phyxel or driver has it); stop that process or "
                        "choose another port");
    }
    if (err == EADDRNOTAVAIL) {
      throw HapticError("haptic UDP device: cannot bind " + at +
                        ": no interface of this machine has that address; use 127.0.0.1");
    }
    if (err == EACCES) {
      throw HapticError("haptic UDP device: cannot bind " + at +
                        ": permission denied (ports below 1024 need privileges); use a port "
                        "above 1024");
    }
    throw HapticError("haptic UDP device: cannot bind " + at + ": " + std::strerror(err));
  }
  sockaddr_in bound{};
  socklen_t len = sizeof bound;
  if (::getsockname(fd_, reinterpret_cast<sockaddr*>(&bound), &len) != 0) {
    const int err = errno;
    ::close(fd_);
    fd_ = -1;
    throw HapticError("haptic UDP device: getsockname on " + where(bind_address, port) +
                      " failed: " + std::strerror(err));
  }
  port_ = ntohs(bound.sin_port);
}

UdpDevice::~UdpDevice() {
  if (fd_ >= 0) ::close(fd_);
}

std::string UdpDevice::name() const {
  return "udp " + where(address_, port_);
}

HapticSample UdpDevice::read(double wall_time) {
  std::lock_guard lock(mutex_);
  std::array<uint8_t, haptic::kMaxMessageSize + 1> buffer;
  for (;;) {
    sockaddr_in from{};
    socklen_t from_len = sizeof from;
    const ssize_t n = ::recvfrom(fd_, buffer.data(), buffer.size(), MSG_TRUNC,
                                 reinterpret_cast<sockaddr*>(&from), &from_len);
    if (n < 0) {
      if (errno == EINTR) continue;
      break;  // EAGAIN: drained (other errors, e.g. ICMP refusals, are not ours to act on)
    }
    ++stats_.datagrams;
    const bool loopback = (ntohl(from.sin_addr.s_addr) >> 24) == 127;
    if (peer_ != 0 ? from.sin_addr.s_addr != peer_ : !loopback) {
      ++stats_.refused;
      continue;
    }
    // MSG_TRUNC: n is the datagram's real length, so an oversized one fails the size check.
    const size_t size = static_cast<size_t>(n);
    haptic::PoseMessage message;
    const haptic::DecodeStatus status =
        size > buffer.size() ? haptic::DecodeStatus::Size
                             : haptic::decode(std::span(buffer.data(), size), message);
    if (status != haptic::DecodeStatus::Ok) {
      ++stats_.malformed;
      ++stats_.malformed_by[static_cast<size_t>(status)];
      continue;
    }
    // The pinned sender, until it goes silent past the timeout (then the next one is pinned,
    // and may have restarted its count: take anything).
    const bool pinned = have_pose_ && wall_time - last_arrival_ <= timeout_;
    const bool same_sender =
        pinned && from_len == sender_len_ && std::memcmp(&from, sender_.data(), from_len) == 0;
    if (pinned && !same_sender) {
      ++stats_.foreign;
      continue;
    }
    if (!same_sender) ++stats_.pins;
    const uint32_t behind = pose_.seq - message.seq;  // modulo 2^32
    if (same_sender && behind != 0 && behind <= 1024) {
      ++stats_.stale;
      continue;
    }
    if (same_sender && behind == 0) {
      ++stats_.stale;  // a duplicate
      continue;
    }
    ++stats_.poses;
    pose_ = message;
    have_pose_ = true;
    last_arrival_ = wall_time;
    std::memcpy(sender_.data(), &from, from_len);
    sender_len_ = from_len;
  }
  HapticSample sample;
  if (have_pose_ && wall_time - last_arrival_ <= timeout_) {
    sample.valid = true;
    sample.pose = {pose_.position, pose_.axis.normalized()};
    sample.buttons = pose_.buttons;
  }
  return sample;
}

void UdpDevice::send(const Vec3& force_on_hand, double wall_time, uint32_t status) {
  std::lock_guard lock(mutex_);
  if (!have_pose_) return;
  haptic::ForceMessage message;
  message.seq = pose_.seq;
  message.phyxel_time = wall_time;
  message.force = force_on_hand;
  message.status = status;
  const auto bytes = haptic::encode(message);
  const ssize_t n = ::sendto(fd_, bytes.data(), bytes.size(), MSG_DONTWAIT,
                             reinterpret_cast<const sockaddr*>(sender_.data()), sender_len_);
  if (n == static_cast<ssize_t>(bytes.size())) {
    ++stats_.forces_sent;
  } else {
    ++stats_.send_errors;
  }
}

UdpDeviceStats UdpDevice::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

}  // namespace phyxel
