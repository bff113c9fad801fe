#include "engine/surgery/haptic_protocol.h"

#include <bit>
#include <cmath>

namespace phyxel::haptic {
namespace {

// Little-endian writing and reading, independent of the host's byte order.
class Writer {
 public:
  explicit Writer(uint8_t* out) : p_(out) {}
  void u16(uint16_t v) {
    for (int i = 0; i < 2; ++i) *p_++ = static_cast<uint8_t>(v >> (8 * i));
  }
  void u32(uint32_t v) {
    for (int i = 0; i < 4; ++i) *p_++ = static_cast<uint8_t>(v >> (8 * i));
  }
  void f64(double d) {
    const uint64_t v = std::bit_cast<uint64_t>(d);
    for (int i = 0; i < 8; ++i) *p_++ = static_cast<uint8_t>(v >> (8 * i));
  }
  void vec3(const Vec3& v) {
    for (int i = 0; i < 3; ++i) f64(v[i]);
  }
  void header(MessageType type) {
    u32(kMagic);
    u16(kVersion);
    u16(static_cast<uint16_t>(type));
  }

 private:
  uint8_t* p_;
};

class Reader {
 public:
  explicit Reader(const uint8_t* in) : p_(in) {}
  uint16_t u16() {
    uint16_t v = 0;
    for (int i = 0; i < 2; ++i) v = static_cast<uint16_t>(v | (uint16_t{*p_++} << (8 * i)));
    return v;
  }
  uint32_t u32() {
    uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= uint32_t{*p_++} << (8 * i);
    return v;
  }
  double f64() {
    uint64_t v = 0;
    for (int i = 0; i < 8; ++i) v |= uint64_t{*p_++} << (8 * i);
    return std::bit_cast<double>(v);
  }
  Vec3 vec3() {
    Vec3 v;
    for (int i = 0; i < 3; ++i) v[i] = f64();
    return v;
  }

 private:
  const uint8_t* p_;
};

// Size, magic, version and type, in that order (the first failure is the reason).
DecodeStatus check_header(std::span<const uint8_t> data, MessageType type, size_t size) {
  if (data.size() < kHeaderSize) return DecodeStatus::Size;
  Reader r(data.data());
  if (r.u32() != kMagic) return DecodeStatus::Magic;
  if (r.u16() != kVersion) return DecodeStatus::Version;
  if (r.u16() != static_cast<uint16_t>(type)) return DecodeStatus::Type;
  if (data.size() != size) return DecodeStatus::Size;
  return DecodeStatus::Ok;
}

}  // namespace

std::string_view to_string(DecodeStatus status) {
  switch (status) {
    case DecodeStatus::Ok:
      return "ok";
    case DecodeStatus::Size:
      return "wrong size";
    case DecodeStatus::Magic:
      return "wrong magic";
    case DecodeStatus::Version:
      return "unsupported version";
    case DecodeStatus::Type:
      return "unexpected message type";
    case DecodeStatus::NonFinite:
      return "non-finite value";
    case DecodeStatus::ZeroAxis:
      return "zero axis";
  }
  return "unknown";
}

std::array<uint8_t, kPoseSize> encode(const PoseMessage& m) {
  std::array<uint8_t, kPoseSize> out{};
  Writer w(out.data());
  w.header(MessageType::Pose);
  w.u32(m.seq);
  w.f64(m.device_time);
  w.vec3(m.position);
  w.vec3(m.axis);
  w.u32(m.buttons);
  return out;
}

std::array<uint8_t, kForceSize> encode(const ForceMessage& m) {
  std::array<uint8_t, kForceSize> out{};
  Writer w(out.data());
  w.header(MessageType::Force);
  w.u32(m.seq);
  w.f64(m.phyxel_time);
  w.vec3(m.force);
  w.u32(m.status);
  return out;
}

DecodeStatus decode(std::span<const uint8_t> data, PoseMessage& out) {
  if (const DecodeStatus s = check_header(data, MessageType::Pose, kPoseSize);
      s != DecodeStatus::Ok) {
    return s;
  }
  Reader r(data.data() + kHeaderSize);
  PoseMessage m;
  m.seq = r.u32();
  m.device_time = r.f64();
  m.position = r.vec3();
  m.axis = r.vec3();
  m.buttons = r.u32();
  if (!std::isfinite(m.device_time) || !m.position.allFinite() || !m.axis.allFinite()) {
    return DecodeStatus::NonFinite;
  }
  if (!(m.axis.norm() >= 1e-9)) return DecodeStatus::ZeroAxis;
  out = m;
  return DecodeStatus::Ok;
}

DecodeStatus decode(std::span<const uint8_t> data, ForceMessage& out) {
  if (const DecodeStatus s = check_header(data, MessageType::Force, kForceSize);
      s != DecodeStatus::Ok) {
    return s;
  }
  Reader r(data.data() + kHeaderSize);
  ForceMessage m;
  m.seq = r.u32();
  m.phyxel_time = r.f64();
  m.force = r.vec3();
  m.status = r.u32();
  if (!std::isfinite(m.phyxel_time) || !m.force.allFinite()) return DecodeStatus::NonFinite;
  out = m;
  return DecodeStatus::Ok;
}

}  // namespace phyxel::haptic
