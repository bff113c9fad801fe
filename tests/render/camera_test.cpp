// Stereo and mono camera math (no GPU): Bourke's off-axis frusta, zero parallax at the focal
// distance, parallax signs, the default camera.
#include <gtest/gtest.h>

#include <cmath>

#include "render/camera.h"
#include "render/splat_renderer.h"

namespace phyxel::render {
namespace {

Camera test_camera() {
  Camera c;
  c.position = Vec3(0.1, -0.4, 0.2);
  c.target = Vec3(0.0, 0.05, 0.0);
  c.up = Vec3::UnitZ();
  c.fov_y_deg = 45;
  c.near = 0.01;
  c.far = 5;
  return c;
}

TEST(StereoCamera, FrustaAreMirrorImagesAndEyesParallel) {
  const Camera cam = test_camera();
  const auto eyes = stereo_eyes(cam, 16.0 / 9.0, 0.064, 0.5);
  const Frustum& l = eyes[0].frustum;
  const Frustum& r = eyes[1].frustum;
  EXPECT_NEAR(l.left, -r.right, 1e-15);
  EXPECT_NEAR(l.right, -r.left, 1e-15);
  EXPECT_EQ(l.top, r.top);
  EXPECT_EQ(l.bottom, r.bottom);
  EXPECT_GT(l.left + l.right, 0);  // the left eye's frustum leans right (towards the centre)
  // Bourke: wd2 = near tan(aperture / 2), shift = 1/2 IPD near / focal.
  const double wd2 = 0.01 * std::tan(22.5 * M_PI / 180);
  EXPECT_NEAR(l.top, wd2, 1e-15);
  EXPECT_NEAR(0.5 * (l.left + l.right), 0.5 * 0.064 * 0.01 / 0.5, 1e-15);
  // Eyes IPD apart along the camera's right vector, same orientation (no toe-in).
  EXPECT_NEAR((eyes[1].position - eyes[0].position).norm(), 0.064, 1e-12);
  EXPECT_NEAR((eyes[1].position - eyes[0].position).normalized().dot(cam.right()), 1.0, 1e-12);
  const Eigen::Matrix3d rot0 = eyes[0].view.block<3, 3>(0, 0),
                        rot1 = eyes[1].view.block<3, 3>(0, 0);
  EXPECT_TRUE(rot0.isApprox(rot1, 1e-15));
}

TEST(StereoCamera, PointsAtTheFocalDistanceProjectToTheSamePixel) {
  const Camera cam = test_camera();
  const double focal = 0.45, w = 640, h = 360;
  const auto eyes = stereo_eyes(cam, w / h, 0.064, focal);
  const Vec3 f = cam.forward(), r = cam.right(), u = cam.true_up();
  for (const auto& [a, b] : {std::pair{0.0, 0.0}, {0.05, 0.02}, {-0.1, -0.04}, {0.12, 0.05}}) {
    const Vec3 p = cam.position + focal * f + a * r + b * u;
    const Eigen::Vector3d pl = project_to_pixel(eyes[0], p, w, h);
    const Eigen::Vector3d pr = project_to_pixel(eyes[1], p, w, h);
    EXPECT_NEAR(pl.x(), pr.x(), 1e-9) << a << ", " << b;
    EXPECT_NEAR(pl.y(), pr.y(), 1e-9) << a << ", " << b;
  }
  // On the axis: the centre of both images.
  const Eigen::Vector3d centre = project_to_pixel(eyes[0], cam.position + focal * f, w, h);
  EXPECT_NEAR(centre.x(), w / 2, 1e-9);
  EXPECT_NEAR(centre.y(), h / 2, 1e-9);
}

TEST(StereoCamera, NearerAndFartherPointsHaveParallaxOfOppositeSign) {
  const Camera cam = test_camera();
  const double focal = 0.45, w = 640, h = 360;
  const auto eyes = stereo_eyes(cam, w / h, 0.064, focal);
  const Vec3 f = cam.forward(), r = cam.right();
  for (double offset : {-0.05, 0.0, 0.07}) {
    const Vec3 near_point = cam.position + 0.25 * f + offset * r;
    const Vec3 far_point = cam.position + 1.5 * f + offset * r;
    const double near_parallax = project_to_pixel(eyes[1], near_point, w, h).x() -
                                 project_to_pixel(eyes[0], near_point, w, h).x();
    const double far_parallax = project_to_pixel(eyes[1], far_point, w, h).x() -
                                project_to_pixel(eyes[0], far_point, w, h).x();
    EXPECT_LT(near_parallax, -1.0) << "nearer than the focal distance: crossed parallax";
    EXPECT_GT(far_parallax, 1.0) << "farther: uncrossed parallax";
    // No vertical parallax with parallel cameras.
    EXPECT_NEAR(project_to_pixel(eyes[1], near_point, w, h).y(),
                project_to_pixel(eyes[0], near_point, w, h).y(), 1e-9);
  }
}

TEST(StereoCamera, ZeroIpdGivesTheMonoEye) {
  const Camera cam = test_camera();
  const EyeView mono = mono_eye(cam, 1.5);
  const auto eyes = stereo_eyes(cam, 1.5, 0.0, 0.3);
  EXPECT_TRUE(mono.view.isApprox(eyes[1].view));
  EXPECT_NEAR(mono.frustum.left, -mono.frustum.right, 1e-15);
  EXPECT_NEAR(mono.frustum.right / mono.frustum.top, 1.5, 1e-12);
  const Eigen::Vector3d t = project_to_pixel(mono, cam.target, 300, 200);
  EXPECT_NEAR(t.x(), 150, 1e-9);
  EXPECT_NEAR(t.y(), 100, 1e-9);
  // Depth: 0 at near, 1 at far.
  EXPECT_NEAR(project_to_pixel(mono, cam.position + cam.near * cam.forward(), 3, 2).z(), 0, 1e-12);
  EXPECT_NEAR(project_to_pixel(mono, cam.position + cam.far * cam.forward(), 3, 2).z(), 1, 1e-12);
  // Up in the world is up in the image (smaller y).
  EXPECT_LT(project_to_pixel(mono, cam.target + 0.01 * cam.true_up(), 300, 200).y(), 100);
  EXPECT_GT(project_to_pixel(mono, cam.target + 0.01 * cam.right(), 300, 200).x(), 150);
}

TEST(StereoCamera, DefaultCameraFramesTheBounds) {
  const Eigen::AlignedBox3d box(Vec3(-0.04, -0.03, 0), Vec3(0.04, 0.03, 0.05));
  const Camera cam = resolve_camera(CameraSettings{}, box, 16.0 / 9.0, "x.json");
  EXPECT_TRUE(cam.target.isApprox(box.center()));
  EXPECT_GT(cam.position.z(), cam.target.z());  // from above
  EXPECT_LT(cam.position.y(), cam.target.y());  // and in front
  const EyeView eye = mono_eye(cam, 16.0 / 9.0);
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner = box.corner(Eigen::AlignedBox3d::CornerType(c));
    const Eigen::Vector3d p = project_to_pixel(eye, corner, 1600, 900);
    EXPECT_GT(p.x(), 0);
    EXPECT_LT(p.x(), 1600);
    EXPECT_GT(p.y(), 0);
    EXPECT_LT(p.y(), 900);
    EXPECT_GT(p.z(), 0);
    EXPECT_LT(p.z(), 1);
  }
  CameraSettings at_target;
  at_target.position = box.center();
  EXPECT_THROW(resolve_camera(at_target, box, 1.0, "x.json"), SceneError);
}

TEST(StereoCamera, FrameSetupLayoutsAndSwap) {
  const Camera cam = test_camera();
  RenderSettings r;
  r.width = 320;
  r.height = 200;
  r.stereo.ipd = 0.06;
  r.stereo.focal_distance = 0.4;
  const FrameSetup mono = make_frame_setup(cam, r, RenderSettings::Mode::Mono);
  EXPECT_EQ(mono.layout, FrameLayout::Mono);
  EXPECT_EQ(mono.frame_width(), 320u);
  const FrameSetup sbs = make_frame_setup(cam, r, RenderSettings::Mode::Stereo);
  EXPECT_EQ(sbs.layout, FrameLayout::SideBySide);
  EXPECT_EQ(sbs.frame_width(), 640u);
  EXPECT_LT(sbs.eyes[0].position.dot(cam.right()), sbs.eyes[1].position.dot(cam.right()));
  r.stereo.swap_eyes = true;
  const FrameSetup swapped = make_frame_setup(cam, r, RenderSettings::Mode::Stereo);
  EXPECT_TRUE(swapped.eyes[0].position.isApprox(sbs.eyes[1].position));
  EXPECT_TRUE(swapped.eyes[1].position.isApprox(sbs.eyes[0].position));
  r.stereo.layout = StereoSettings::Layout::Anaglyph;
  EXPECT_EQ(make_frame_setup(cam, r, RenderSettings::Mode::Stereo).frame_width(), 320u);
  // Without a focal distance: zero parallax at the target.
  r.stereo.focal_distance.reset();
  r.stereo.swap_eyes = false;
  const FrameSetup at_target = make_frame_setup(cam, r, RenderSettings::Mode::Stereo);
  EXPECT_NEAR(project_to_pixel(at_target.eyes[0], cam.target, 320, 200).x(),
              project_to_pixel(at_target.eyes[1], cam.target, 320, 200).x(), 1e-9);
}

}  // namespace
}  // namespace phyxel::render
