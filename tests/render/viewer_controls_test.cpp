// The window viewer's controls (render/viewer_controls.h) without a window: the orbit camera
// under drags and the wheel, and what the keys ask of the simulation loop.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

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

TEST(ViewerControls, STogglesStereoPTakesAPictureAndQOrEscapeQuit) {
  ViewerControls v(oblique_camera());
  EXPECT_FALSE(v.take_stereo_toggle());
  v.key(ViewerKey::S);
  EXPECT_TRUE(v.take_stereo_toggle());
  EXPECT_FALSE(v.take_stereo_toggle()) << "once per press";
  v.key(ViewerKey::S);
  v.key(ViewerKey::S);
  EXPECT_FALSE(v.take_stereo_toggle()) << "two presses before a frame cancel";
  EXPECT_FALSE(v.take_screenshot());
  v.key(ViewerKey::P);
  v.key(ViewerKey::P);
  EXPECT_TRUE(v.take_screenshot());
  EXPECT_FALSE(v.take_screenshot()) << "one picture per frame however many presses";
  v.key(ViewerKey::Other);
  EXPECT_FALSE(v.quit());
  v.key(ViewerKey::Escape);
  EXPECT_TRUE(v.quit());
  ViewerControls w(oblique_camera());
  w.key(ViewerKey::Q);
  EXPECT_TRUE(w.quit());
}

TEST(ViewerToolControls, ADragOfNPixelsMovesTheTipByThePixelSizeAtItsDepth) {
  Camera c = oblique_camera();
  c.fov_y_deg = 40;
  const double width = 640, height = 400;
  const Vec3 tip = c.target + Vec3(0.02, -0.03, 0.01);
  const double depth = (tip - c.position).dot(c.forward());
  const double pixel = 2 * depth * std::tan(20 * M_PI / 180) / height;
  const Vec3 right = drag_in_view_plane(c, height, tip, 50, 0);
  EXPECT_NEAR(right.norm(), 50 * pixel, 1e-12);
  EXPECT_NEAR(right.normalized().dot(c.right()), 1.0, 1e-12);
  const Vec3 down = drag_in_view_plane(c, height, tip, 0, 30);
  EXPECT_NEAR(down.norm(), 30 * pixel, 1e-12);
  EXPECT_NEAR(down.normalized().dot(c.true_up()), -1.0, 1e-12) << "y grows downwards";
  // The tip stays at its depth and its image follows the cursor exactly.
  const Vec3 moved = tip + drag_in_view_plane(c, height, tip, 37, -21);
  EXPECT_NEAR((moved - c.position).dot(c.forward()), depth, 1e-12);
  const Eigen::Vector2d before = view_pixel(c, width, height, tip);
  const Eigen::Vector2d after = view_pixel(c, width, height, moved);
  EXPECT_NEAR(after.x() - before.x(), 37, 1e-9);
  EXPECT_NEAR(after.y() - before.y(), -21, 1e-9);
  // Twice as deep: twice as far per pixel.
  const Vec3 deep = c.position + 2 * (tip - c.position);
  EXPECT_NEAR(drag_in_view_plane(c, height, deep, 50, 0).norm(), 100 * pixel, 1e-12);
}

TEST(ViewerToolControls, TheWheelMovesTheTipAlongTheViewRay) {
  const Camera c = oblique_camera();
  const Vec3 tip = c.target + Vec3(0.02, -0.03, 0.01);
  const Vec3 pushed = push_along_view(c, tip, 0.1);
  EXPECT_NEAR((pushed - c.position).norm(), 1.1 * (tip - c.position).norm(), 1e-12);
  EXPECT_LT((pushed - c.position).normalized().cross((tip - c.position).normalized()).norm(), 1e-12)
      << "on the ray from the eye through the tip";
  const Eigen::Vector2d a = view_pixel(c, 320, 200, tip), b = view_pixel(c, 320, 200, pushed);
  EXPECT_LT((a - b).norm(), 1e-9) << "its image does not move";
}

TEST(ViewerToolControls, RightOrShiftDragMovesTheNearestHapticToolShiftWheelPushesIt) {
  const Camera c = oblique_camera();
  ViewerControls v(c);
  v.set_view_size(320, 200);
  const Vec3 a = c.target + 0.03 * c.right(), b = c.target - 0.03 * c.right();
  v.set_haptic_tools({{2, {a, Vec3::UnitZ()}}, {5, {b, Vec3::UnitX()}}});
  const Eigen::Vector2d at_b = view_pixel(c, 320, 200, b);
  // A right drag that starts near b's tip moves b only, by the drag, and not the camera.
  v.button(ViewerButton::Right, true, at_b.x() + 3, at_b.y() - 2, false);
  v.cursor(at_b.x() + 23, at_b.y() + 8);
  v.button(ViewerButton::Right, false, at_b.x() + 23, at_b.y() + 8, false);
  EXPECT_EQ(v.take_moved_tools(), std::vector<size_t>{1});
  EXPECT_TRUE(v.take_moved_tools().empty()) << "reported once";
  const HapticTarget& moved = v.haptic_tools()[1];
  EXPECT_EQ(moved.tool, 5u);
  EXPECT_LT((moved.pose.position - (b + drag_in_view_plane(c, 200, b, 20, 10))).norm(), 1e-12);
  EXPECT_EQ(moved.pose.axis, Vec3::UnitX());
  EXPECT_EQ(v.haptic_tools()[0].pose.position, a);
  EXPECT_LT((v.orbit().position() - c.position).norm(), 1e-12) << "the camera stays";
  // Shift + left drag near a, in the right half of a side-by-side window (x + eye width).
  const Eigen::Vector2d at_a = view_pixel(c, 320, 200, a);
  v.button(ViewerButton::Left, true, at_a.x() + 320, at_a.y(), true);
  v.cursor(at_a.x() + 320, at_a.y() + 15);
  v.button(ViewerButton::Left, false, at_a.x() + 320, at_a.y() + 15, true);
  EXPECT_EQ(v.take_moved_tools(), std::vector<size_t>{0});
  EXPECT_NEAR(view_pixel(c, 320, 200, v.haptic_tools()[0].pose.position).y() - at_a.y(), 15, 1e-9);
  // Shift + wheel pushes the last moved tool (a) along the view; the zoom stays.
  const Vec3 before = v.haptic_tools()[0].pose.position;
  v.scroll(2, true);
  EXPECT_EQ(v.take_moved_tools(), std::vector<size_t>{0});
  EXPECT_LT((v.haptic_tools()[0].pose.position -
             push_along_view(c, before, 2 * ViewerControls::kToolPushPerNotch))
                .norm(),
            1e-12);
  EXPECT_NEAR(v.orbit().distance, (c.position - c.target).norm(), 1e-12);
  v.scroll(1);  // no shift: zoom
  EXPECT_NEAR(v.orbit().distance, 0.9 * (c.position - c.target).norm(), 1e-12);
  EXPECT_TRUE(v.take_moved_tools().empty());
}

TEST(ViewerToolControls, WithoutHapticToolsShiftDragOrbitsAndRightDragDoesNothing) {
  const Camera c = oblique_camera();
  ViewerControls v(c);
  v.button(ViewerButton::Right, true, 100, 100, false);
  v.cursor(150, 100);
  v.button(ViewerButton::Right, false, 150, 100, false);
  EXPECT_LT((v.orbit().position() - c.position).norm(), 1e-15);
  v.button(ViewerButton::Left, true, 100, 100, true);
  v.cursor(150, 100);
  EXPECT_NEAR(v.orbit().yaw, -50 * ViewerControls::kRadiansPerPixel, 1e-12);
  v.scroll(1, true);
  EXPECT_NEAR(v.orbit().distance, 0.9 * (c.position - c.target).norm(), 1e-12);
  EXPECT_TRUE(v.take_moved_tools().empty());
}

TEST(ViewerToolControls, PathToolsFollowTheirPathsHapticToolsTheirTargets) {
  ToolDesc path, haptic;
  path.shape = {ToolShape::Type::Capsule, 0.002, 0.03};
  path.path = {{0.0, Vec3(0, 0, 0), Vec3::UnitZ()}, {1.0, Vec3(0.1, 0, 0), Vec3::UnitZ()}};
  haptic.shape = {ToolShape::Type::Sphere, 0.004, 0};
  haptic.control = ToolDesc::Control::Haptic;
  haptic.path = {{0.5, Vec3(0, 0.02, 0.01), Vec3::UnitY()}};
  const std::vector<ToolDesc> tools = {path, haptic};
  const std::vector<HapticTarget> targets = haptic_targets(tools);
  ASSERT_EQ(targets.size(), 1u);
  EXPECT_EQ(targets[0].tool, 1u);
  EXPECT_EQ(targets[0].pose.position, Vec3(0, 0.02, 0.01));
  EXPECT_EQ(targets[0].pose.axis, Vec3::UnitY());
  std::vector<HapticTarget> moved = targets;
  moved[0].pose.position = Vec3(0.05, 0.05, 0.05);
  const std::vector<ToolDrawable> drawn = viewer_tools(tools, 0.25, moved);
  ASSERT_EQ(drawn.size(), 2u);
  EXPECT_LT((drawn[0].pose.position - Vec3(0.025, 0, 0)).norm(), 1e-15) << "pose_at(path, t)";
  EXPECT_EQ(drawn[0].shape.length, 0.03);
  EXPECT_EQ(drawn[1].pose.position, Vec3(0.05, 0.05, 0.05)) << "at the mouse's target";
  EXPECT_EQ(drawn[1].shape.radius, 0.004);
  // With haptic_pose the viewer draws where it says (the coupled tool), given the target.
  const std::vector<ToolDrawable> coupled =
      viewer_tools(tools, 0.25, moved, [](size_t tool, const ToolPose& target) {
        EXPECT_EQ(tool, 1u);
        return ToolPose{target.position - Vec3(0, 0, 0.01), target.axis};
      });
  EXPECT_EQ(coupled[1].pose.position, Vec3(0.05, 0.05, 0.04));
}

TEST(ViewerControls, TheTitleSaysWhatEachToolFeelsAndWhetherItLags) {
  EXPECT_EQ(tool_note("probe", 0.12345, 12), "probe 0.123 N (12 contacts)");
  EXPECT_EQ(tool_note("probe", 0.5, 3, 0.331),
            "probe 0.500 N (3 contacts, lagging the hand at its top speed 0.331 m/s)");
}

TEST(ViewerControls, TheTitleSaysStepPauseModeAndRate) {
  EXPECT_EQ(viewer_title("scenes/beam.json", 120, true, true, 29.96),
            "phyxel view scenes/beam.json  step 120 (paused)  stereo  30.0 fps");
  EXPECT_EQ(viewer_title("b.json", 0, false, false, 5),
            "phyxel view b.json  step 0  mono  5.0 fps");
}

}  // namespace
}  // namespace phyxel::render
