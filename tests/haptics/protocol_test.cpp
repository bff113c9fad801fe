// The haptic UDP protocol: byte layout, round trips, and every reason a datagram is refused.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "engine/surgery/haptic_protocol.h"

namespace phyxel::haptic {
namespace {

PoseMessage sample_pose() {
  PoseMessage m;
  m.seq = 0x01020304;
  m.device_time = 12.5;
  m.position = Vec3(0.1, -0.25, 1.0 / 3.0);
  m.axis = Vec3(0.6, 0.0, -0.8);
  m.buttons = 0xA5;
  return m;
}

ForceMessage sample_force() {
  ForceMessage m;
  m.seq = 0xDEADBEEF;
  m.phyxel_time = 1e6 + 0.125;
  m.force = Vec3(-1.5, 2.0 / 7.0, 8.0);
  m.status = kStatusInContact | kStatusClamped;
  return m;
}

double f64_at(const uint8_t* p) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= uint64_t{p[i]} << (8 * i);
  double d;
  std::memcpy(&d, &v, 8);
  return d;
}

uint32_t u32_at(const uint8_t* p) {
  return uint32_t{p[0]} | uint32_t{p[1]} << 8 | uint32_t{p[2]} << 16 | uint32_t{p[3]} << 24;
}

TEST(HapticProtocol, PoseLayoutIsLittleEndianAsDocumented) {
  const auto b = encode(sample_pose());
  ASSERT_EQ(b.size(), 72u);
  EXPECT_EQ(std::memcmp(b.data(), "PXHP", 4), 0);
  EXPECT_EQ(b[4], 1);  // version 1, u16
  EXPECT_EQ(b[5], 0);
  EXPECT_EQ(b[6], 1);  // type pose, u16
  EXPECT_EQ(b[7], 0);
  EXPECT_EQ(b[8], 0x04);  // seq, least significant byte first
  EXPECT_EQ(b[11], 0x01);
  EXPECT_EQ(f64_at(&b[12]), 12.5);
  EXPECT_EQ(f64_at(&b[20]), 0.1);
  EXPECT_EQ(f64_at(&b[28]), -0.25);
  EXPECT_EQ(f64_at(&b[36]), 1.0 / 3.0);
  EXPECT_EQ(f64_at(&b[44]), 0.6);
  EXPECT_EQ(f64_at(&b[52]), 0.0);
  EXPECT_EQ(f64_at(&b[60]), -0.8);
  EXPECT_EQ(u32_at(&b[68]), 0xA5u);
}

TEST(HapticProtocol, ForceLayoutIsLittleEndianAsDocumented) {
  const auto b = encode(sample_force());
  ASSERT_EQ(b.size(), 48u);
  EXPECT_EQ(u32_at(&b[0]), kMagic);
  EXPECT_EQ(b[6], 2);  // type force
  EXPECT_EQ(u32_at(&b[8]), 0xDEADBEEFu);
  EXPECT_EQ(f64_at(&b[12]), 1e6 + 0.125);
  EXPECT_EQ(f64_at(&b[20]), -1.5);
  EXPECT_EQ(f64_at(&b[28]), 2.0 / 7.0);
  EXPECT_EQ(f64_at(&b[36]), 8.0);
  EXPECT_EQ(u32_at(&b[44]), 3u);
}

TEST(HapticProtocol, PoseRoundTripIsExact) {
  const PoseMessage in = sample_pose();
  const auto bytes = encode(in);
  PoseMessage out;
  ASSERT_EQ(decode(bytes, out), DecodeStatus::Ok);
  EXPECT_EQ(out.seq, in.seq);
  EXPECT_EQ(out.device_time, in.device_time);
  EXPECT_EQ(out.position, in.position);
  EXPECT_EQ(out.axis, in.axis);  // not normalized by decoding
  EXPECT_EQ(out.buttons, in.buttons);
}

TEST(HapticProtocol, ForceRoundTripIsExact) {
  const ForceMessage in = sample_force();
  const auto bytes = encode(in);
  ForceMessage out;
  ASSERT_EQ(decode(bytes, out), DecodeStatus::Ok);
  EXPECT_EQ(out.seq, in.seq);
  EXPECT_EQ(out.phyxel_time, in.phyxel_time);
  EXPECT_EQ(out.force, in.force);
  EXPECT_EQ(out.status, in.status);
}

// Decoding a pose from `bytes` must fail with `want` and leave `out` untouched.
void expect_pose_refused(const std::vector<uint8_t>& bytes, DecodeStatus want) {
  PoseMessage out;
  out.seq = 77;
  EXPECT_EQ(decode(bytes, out), want) << to_string(want);
  EXPECT_EQ(out.seq, 77u);
}

std::vector<uint8_t> pose_bytes(const PoseMessage& m) {
  const auto a = encode(m);
  return {a.begin(), a.end()};
}

TEST(HapticProtocol, MalformedPosesAreRefusedWithTheirReason) {
  const std::vector<uint8_t> good = pose_bytes(sample_pose());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();

  expect_pose_refused({}, DecodeStatus::Size);
  expect_pose_refused({good.begin(), good.begin() + 7}, DecodeStatus::Size);  // short header
  expect_pose_refused({good.begin(), good.end() - 1}, DecodeStatus::Size);    // truncated
  std::vector<uint8_t> longer = good;
  longer.push_back(0);
  expect_pose_refused(longer, DecodeStatus::Size);

  std::vector<uint8_t> magic = good;
  magic[0] ^= 0xFF;
  expect_pose_refused(magic, DecodeStatus::Magic);
  std::vector<uint8_t> version = good;
  version[4] = 2;
  expect_pose_refused(version, DecodeStatus::Version);
  std::vector<uint8_t> type = good;
  type[6] = 2;  // a force header on a pose body
  expect_pose_refused(type, DecodeStatus::Type);
  type[6] = 9;  // no such type
  expect_pose_refused(type, DecodeStatus::Type);
  const auto force = encode(sample_force());
  expect_pose_refused({force.begin(), force.end()}, DecodeStatus::Type);

  PoseMessage m = sample_pose();
  m.device_time = inf;
  expect_pose_refused(pose_bytes(m), DecodeStatus::NonFinite);
  m = sample_pose();
  m.position.y() = nan;
  expect_pose_refused(pose_bytes(m), DecodeStatus::NonFinite);
  m = sample_pose();
  m.axis.z() = -inf;
  expect_pose_refused(pose_bytes(m), DecodeStatus::NonFinite);
  m = sample_pose();
  m.axis = Vec3::Zero();
  expect_pose_refused(pose_bytes(m), DecodeStatus::ZeroAxis);
  m.axis = Vec3(1e-12, 0, 0);
  expect_pose_refused(pose_bytes(m), DecodeStatus::ZeroAxis);
}

TEST(HapticProtocol, MalformedForcesAreRefusedWithTheirReason) {
  const auto good = encode(sample_force());
  ForceMessage out;
  std::vector<uint8_t> b(good.begin(), good.end());
  b.pop_back();
  EXPECT_EQ(decode(b, out), DecodeStatus::Size);
  b.assign(good.begin(), good.end());
  b[3] = 0;
  EXPECT_EQ(decode(b, out), DecodeStatus::Magic);
  b.assign(good.begin(), good.end());
  b[5] = 1;  // version 257
  EXPECT_EQ(decode(b, out), DecodeStatus::Version);
  const auto pose = encode(sample_pose());
  EXPECT_EQ(decode(pose, out), DecodeStatus::Type);
  ForceMessage m = sample_force();
  m.force.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(decode(encode(m), out), DecodeStatus::NonFinite);
  m = sample_force();
  m.phyxel_time = std::numeric_limits<double>::infinity();
  EXPECT_EQ(decode(encode(m), out), DecodeStatus::NonFinite);
}

TEST(HapticProtocol, EveryStatusHasAName) {
  for (size_t i = 0; i < kDecodeStatusCount; ++i) {
    EXPECT_NE(to_string(static_cast<DecodeStatus>(i)), "unknown");
  }
}

}  // namespace
}  // namespace phyxel::haptic
