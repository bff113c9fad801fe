// libFuzzer target: the haptic protocol's decoder (engine/surgery/haptic_protocol.h) on
// arbitrary datagrams, as UdpDevice and the reference driver receive them. A datagram that
// decodes must hold finite values and encode back to the same bytes.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <span>

#include "engine/surgery/haptic_protocol.h"

namespace {

bool finite(const phyxel::Vec3& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::span<const uint8_t> bytes(data, size);
  phyxel::haptic::PoseMessage pose;
  if (phyxel::haptic::decode(bytes, pose) == phyxel::haptic::DecodeStatus::Ok) {
    if (!finite(pose.position) || !finite(pose.axis)) std::abort();
    const auto again = phyxel::haptic::encode(pose);
    if (again.size() != size || std::memcmp(again.data(), data, size) != 0) std::abort();
  }
  phyxel::haptic::ForceMessage force;
  if (phyxel::haptic::decode(bytes, force) == phyxel::haptic::DecodeStatus::Ok) {
    if (!finite(force.force)) std::abort();
    const auto again = phyxel::haptic::encode(force);
    if (again.size() != size || std::memcmp(again.data(), data, size) != 0) std::abort();
  }
  return 0;
}
