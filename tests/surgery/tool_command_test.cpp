// ToolTrack::command (engine/surgery/tool_track.h): a tool taken off its path moves to the pose
// it is given over the substeps it is given, linearly, then stays (the Python module's
// set_tool_pose); a live (haptic) tool follows its pose source no faster than its top speed.
#include <gtest/gtest.h>

#include <vector>

#include "engine/surgery/tool_track.h"

namespace phyxel {
namespace {

ToolDesc probe() {
  ToolDesc t;
  t.name = "probe";
  t.shape.type = ToolShape::Type::Capsule;
  t.shape.radius = 0.002;
  t.shape.length = 0.02;
  t.path = {{0.0, Vec3(0, 0, 0.05), Vec3::UnitZ()}, {1.0, Vec3(0, 0, 0.0), Vec3::UnitZ()}};
  return t;
}

TEST(ToolCommand, MovesToThePoseOverItsSubstepsThenStays) {
  ToolTrack track({probe()}, {});
  const double dt = 0.01;
  track.motions(0, 10, dt);  // on its path: z 0.05 -> 0.045
  EXPECT_NEAR(track.poses()[0].position.z(), 0.045, 1e-15);
  track.command(0, {Vec3(0.01, 0, 0.06), Vec3(0, 0, 2)}, 4);
  const std::vector<ToolMotion> m = track.motions(10, 6, dt);
  ASSERT_EQ(m.size(), 6u);
  EXPECT_NEAR(m[0].from.position.z(), 0.045, 1e-15);
  for (int k = 0; k < 4; ++k) {  // a quarter of the way each substep
    const double s = (k + 1) / 4.0;
    EXPECT_NEAR(m[k].to.position.x(), 0.01 * s, 1e-15) << k;
    EXPECT_NEAR(m[k].to.position.z(), 0.045 + 0.015 * s, 1e-15) << k;
  }
  for (int k = 3; k < 6; ++k) EXPECT_EQ(m[k].to.position, Vec3(0.01, 0, 0.06)) << k;
  EXPECT_EQ(track.poses()[0].axis, Vec3::UnitZ());                 // normalised
  const std::vector<ToolMotion> later = track.motions(16, 3, dt);  // not back to the path
  for (const ToolMotion& mo : later) EXPECT_EQ(mo.to.position, Vec3(0.01, 0, 0.06));
  const Bounds b = track.swept_bounds(0.16, 0.19);
  EXPECT_LE(b.min.z(), 0.06 - 0.002 + 1e-15);
  EXPECT_GE(b.max.z(), 0.06 + 0.02);
}

// A pose source 3 cm away (a haptic loop run ahead of a stalled physics): the tool moves
// 0.3 m/s x dt a substep toward it, then stays.
TEST(ToolTrackLive, MovesNoFasterThanItsTopSpeed) {
  ToolDesc hand = probe();
  hand.control = ToolDesc::Control::Haptic;
  const Vec3 device(0, 0, 0.02);
  const auto source = [&](size_t, double) { return ToolPose{device, Vec3::UnitZ()}; };
  EXPECT_THROW(ToolTrack({hand}, source), std::invalid_argument);  // no top speed
  EXPECT_THROW(ToolTrack({hand}, source, {0.0}), std::invalid_argument);
  ToolTrack track({hand}, source, {0.3});
  const double dt = 0.01;
  std::vector<ToolMotion> m = track.motions(0, 5, dt);
  for (int k = 0; k < 5; ++k) {
    EXPECT_NEAR(m[k].from.position.z() - m[k].to.position.z(), 0.3 * dt, 1e-15) << k;
    EXPECT_EQ(m[k].to.axis, Vec3::UnitZ());
  }
  m = track.motions(5, 5, dt);  // 0.015 m left, 0.015 m of travel: arrives
  EXPECT_NEAR(m.back().to.position.z(), 0.02, 1e-15);
  m = track.motions(10, 2, dt);
  EXPECT_EQ(m.back().to.position, device);
}

TEST(ToolCommand, UnknownToolIsRefused) {
  ToolTrack track({probe()}, {});
  EXPECT_THROW(track.command(1, {}, 1), std::out_of_range);
}

}  // namespace
}  // namespace phyxel
