// The window viewer's controls (render/viewer_controls.h) without a window: the orbit camera
// under drags and the wheel, and what the keys ask of the simulation loop.
#include <gtest/gtest.h>

#include <cmath>

#include "render/viewer_controls.h"

namespace phyxel::render {
namespace {

Camera oblique_camera() {
  Camera c;
  c.position = Vec3(0.3, -0.4, 0.2);
  c.target = Vec3(0.01, 0.02, 0.03);
  c.up = Vec3::UnitZ();
  return c;
}

TEST(ViewerControls, TheOrbitStartsAtTheScenesCamera) {
  const Camera c = oblique_camera();
  EXPECT_LT((Orbit(c).position() - c.position).norm(), 1e-12);
  // Looking straight down the up axis, where the horizontal direction is undefined.
  Camera top = c;
  top.position = c.target + Vec3(0, 0, 0.5);
  top.up = Vec3::UnitY();
  EXPECT_LT((Orbit(top).position() - top.position).norm(), 1e-12);
  Camera above = c;
  above.position = c.target + Vec3(0, 0, 0.5);  // along up itself
  const Orbit o(above);
  EXPECT_TRUE(o.position().allFinite());
  EXPECT_LT((o.position() - above.position).norm(), 1e-12);
  EXPECT_NEAR(o.front.norm(), 1.0, 1e-12);
  ViewerControls v(above);  // and a drag from there keeps the distance
  v.button(true, 0, 0);
  v.cursor(30, 40);
  EXPECT_NEAR((v.orbit().position() - above.target).norm(), 0.5, 1e-12);
}

TEST(ViewerControls, DraggingOrbitsAroundTheTargetAtAFixedDistance) {
  const Camera c = oblique_camera();
  ViewerControls v(c);
  const double distance = (c.position - c.target).norm();
  const double height = (c.position - c.target).dot(c.up);
  v.button(true, 100, 100);
  v.cursor(200, 100);  // 100 pixels right: yaw -0.8 rad about up
  const Vec3 p = v.orbit().position();
  EXPECT_NEAR((p - c.target).norm(), distance, 1e-12);
  EXPECT_NEAR((p - c.target).dot(c.up), height, 1e-12) << "a horizontal drag keeps the height";
  const Vec3 a = (c.position - c.target) - height * c.up;
  const Vec3 b = (p - c.target) - height * c.up;
  const double angle = std::atan2(a.cross(b).dot(c.up), a.dot(b));
  EXPECT_NEAR(angle, -100 * ViewerControls::kRadiansPerPixel, 1e-12);
  // Without the button held the cursor moves nothing.
  v.button(false, 200, 100);
  v.cursor(400, 300);
  EXPECT_LT((v.orbit().position() - p).norm(), 1e-15);
}

TEST(ViewerControls, PitchStopsShortOfTheUpAxis) {
  ViewerControls v(oblique_camera());
  v.button(true, 0, 0);
  v.cursor(0, 10000);  // far past the pole
  EXPECT_DOUBLE_EQ(v.orbit().pitch, ViewerControls::kMaxPitch);
  v.cursor(0, -10000);
  EXPECT_DOUBLE_EQ(v.orbit().pitch, -ViewerControls::kMaxPitch);
  const Camera seen = v.orbit().camera(oblique_camera());
  EXPECT_GT(seen.right().norm(), 0.99) << "the view never lines up with up";
}

TEST(ViewerControls, TheWheelZoomsTowardsAndAwayFromTheTarget) {
  const Camera c = oblique_camera();
  ViewerControls v(c);
  const double d = (c.position - c.target).norm();
  v.scroll(2);
  EXPECT_NEAR(v.orbit().distance, d * 0.81, 1e-12);
  v.scroll(-2);
  EXPECT_NEAR(v.orbit().distance, d, 1e-12);
  const Camera moved = v.orbit().camera(c);
  EXPECT_EQ(moved.target, c.target);
  EXPECT_EQ(moved.fov_y_deg, c.fov_y_deg);
}

TEST(ViewerControls, SpacePausesAndNStepsOnceWhilePaused) {
  ViewerControls v(oblique_camera());
  EXPECT_EQ(v.steps_for_frame(10), 10);
  v.key(ViewerKey::N);  // running: n does nothing
  EXPECT_EQ(v.steps_for_frame(10), 10);
  v.key(ViewerKey::Space);
  EXPECT_TRUE(v.paused());
  EXPECT_EQ(v.steps_for_frame(10), 0);
  v.key(ViewerKey::N);
  EXPECT_EQ(v.steps_for_frame(10), 1);
  EXPECT_EQ(v.steps_for_frame(10), 0) << "one step per press";
  v.key(ViewerKey::Space);
  EXPECT_FALSE(v.paused());
  EXPECT_EQ(v.steps_for_frame(7), 7);
}

TEST(ViewerControls, STogglesStereoAndQOrEscapeQuit) {
  ViewerControls v(oblique_camera());
  EXPECT_FALSE(v.take_stereo_toggle());
  v.key(ViewerKey::S);
  EXPECT_TRUE(v.take_stereo_toggle());
  EXPECT_FALSE(v.take_stereo_toggle()) << "once per press";
  v.key(ViewerKey::S);
  v.key(ViewerKey::S);
  EXPECT_FALSE(v.take_stereo_toggle()) << "two presses before a frame cancel";
  v.key(ViewerKey::Other);
  EXPECT_FALSE(v.quit());
  v.key(ViewerKey::Escape);
  EXPECT_TRUE(v.quit());
  ViewerControls w(oblique_camera());
  w.key(ViewerKey::Q);
  EXPECT_TRUE(w.quit());
}

TEST(ViewerControls, TheTitleSaysStepPauseModeAndRate) {
  EXPECT_EQ(viewer_title("scenes/beam.json", 120, true, true, 29.96),
            "phyxel view scenes/beam.json  step 120 (paused)  stereo  30.0 fps");
  EXPECT_EQ(viewer_title("b.json", 0, false, false, 5),
            "phyxel view b.json  step 0  mono  5.0 fps");
}

}  // namespace
}  // namespace phyxel::render
