// The haptic UDP protocol (docs/haptics.md): what an external device driver (a vendor SDK, a
// ROS bridge, tools/haptic_udp_client) and phyxel's UdpDevice exchange. One datagram is one
// message; every field is little-endian, doubles are IEEE 754 binary64, no padding.
//
//   header (8 bytes): magic u32 = 0x50485850 (the bytes "PXHP"), version u16 = 1, type u16
//   pose  (type 1, device -> phyxel, 72 bytes): header, seq u32, device time f64 (s),
//         position 3 x f64 (m), axis 3 x f64 (the shaft direction, any non-zero length),
//         buttons u32
//   force (type 2, phyxel -> device, 48 bytes): header, seq u32 (the last pose's, echoed),
//         phyxel time f64 (s), force 3 x f64 (N, to apply to the hand), status u32
//
// A message of another size, magic, version or type, with a non-finite number or (pose) an
// axis shorter than 1e-9 is malformed: decoding refuses it and says why.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "engine/geometry/tool.h"

namespace phyxel::haptic {

inline constexpr uint32_t kMagic = 0x50485850;  // "PXHP" as little-endian bytes
inline constexpr uint16_t kVersion = 1;
inline constexpr size_t kHeaderSize = 8;
inline constexpr size_t kPoseSize = 72;
inline constexpr size_t kForceSize = 48;
inline constexpr size_t kMaxMessageSize = kPoseSize;

enum class MessageType : uint16_t { Pose = 1, Force = 2 };

// Status flags of a force message.
inline constexpr uint32_t kStatusInContact = 1u << 0;  // the tool touches tissue
inline constexpr uint32_t kStatusClamped = 1u << 1;    // the force was clamped to max_force

struct PoseMessage {
  uint32_t seq = 0;
  double device_time = 0;  // s, the driver's clock
  Vec3 position = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();
  uint32_t buttons = 0;
};

struct ForceMessage {
  uint32_t seq = 0;        // the seq of the pose this answers
  double phyxel_time = 0;  // s, phyxel's haptic clock
  Vec3 force = Vec3::Zero();
  uint32_t status = 0;
};

// Why a datagram was refused (Ok: it was not).
enum class DecodeStatus { Ok, Size, Magic, Version, Type, NonFinite, ZeroAxis };
inline constexpr size_t kDecodeStatusCount = 7;
std::string_view to_string(DecodeStatus status);

std::array<uint8_t, kPoseSize> encode(const PoseMessage& message);
std::array<uint8_t, kForceSize> encode(const ForceMessage& message);

// Decode one datagram; `out` is written only when the result is Ok.
DecodeStatus decode(std::span<const uint8_t> data, PoseMessage& out);
DecodeStatus decode(std::span<const uint8_t> data, ForceMessage& out);

}  // namespace phyxel::haptic
