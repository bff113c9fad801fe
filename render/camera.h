// Cameras: the scene's `camera` resolved against the scene's bounds, the mono eye, and the
// parallel stereo pair with asymmetric (off-axis) frusta of Bourke, "Calculating stereo
// pairs" (the paper's section VII, Fig. 20):
//
//   wd2 = near tan(aperture / 2), top = wd2, bottom = -wd2,
//   left/right = -+ aspect wd2 + shift, shift = -+ 1/2 IPD near / focal (left eye +, right -)
//
// with the eyes at -+ IPD/2 along the camera's right vector, both looking along the same
// direction (no toe-in, so no vertical parallax). A point at the focal distance on the view
// axis projects to the centre of both images; nearer points have negative (crossed) parallax,
// farther points positive parallax.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>

#include "engine/scene/scene.h"

namespace phyxel::render {

struct Camera {
  Vec3 position = Vec3(0, -1, 0);
  Vec3 target = Vec3::Zero();
  Vec3 up = Vec3::UnitZ();
  double fov_y_deg = 45;
  double near = 0.01, far = 10;

  Vec3 forward() const { return (target - position).normalized(); }
  Vec3 right() const { return forward().cross(up).normalized(); }
  Vec3 true_up() const { return right().cross(forward()); }
};

// The scene's camera with unset position/target filled in: target the centre of `bounds`,
// position on a line above and in front of it (along -y, raised towards `up`) at the
// distance where the bounds' enclosing sphere fills the field of view (of width/height
// `aspect`). Throws SceneError when position equals target or up is parallel to the view.
Camera resolve_camera(const CameraSettings& settings, const Eigen::AlignedBox3d& bounds,
                      double aspect, const std::string& scene_file = {});

// Frustum at the near plane (glFrustum's left, right, bottom, top, near, far), eye space.
struct Frustum {
  double left = -1, right = 1, bottom = -1, top = 1, near = 0.01, far = 10;
};

struct EyeView {
  Vec3 position = Vec3::Zero();                        // world
  Eigen::Matrix4d view = Eigen::Matrix4d::Identity();  // world -> eye (looks down -z, y up)
  Frustum frustum;
};

// The symmetric frustum of a single camera.
EyeView mono_eye(const Camera& camera, double aspect);
// {left eye, right eye}, `ipd` >= 0 apart, zero parallax at `focal_distance` > 0.
std::array<EyeView, 2> stereo_eyes(const Camera& camera, double aspect, double ipd,
                                   double focal_distance);

// Where a world point lands in an eye's image of width x height pixels: x to the right and y
// down from the top-left corner (pixel centres at +0.5), z the linear depth (0 at near, 1 at
// far), exactly as the shaders project (render/shaders/splat_common.glsl).
Eigen::Vector3d project_to_pixel(const EyeView& eye, const Vec3& world, double width,
                                 double height);

}  // namespace phyxel::render
