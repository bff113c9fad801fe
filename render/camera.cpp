#include "render/camera.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace phyxel::render {
namespace {

double radians(double deg) {
  return deg * std::numbers::pi / 180.0;
}

// World -> eye: rows right, up, -forward; the eye at `eye`.
Eigen::Matrix4d look_along(const Vec3& eye, const Vec3& right, const Vec3& up,
                           const Vec3& forward) {
  Eigen::Matrix4d v = Eigen::Matrix4d::Identity();
  v.block<1, 3>(0, 0) = right.transpose();
  v.block<1, 3>(1, 0) = up.transpose();
  v.block<1, 3>(2, 0) = -forward.transpose();
  v(0, 3) = -right.dot(eye);
  v(1, 3) = -up.dot(eye);
  v(2, 3) = forward.dot(eye);
  return v;
}

[[noreturn]] void fail(const std::string& file, const std::string& key, const std::string& what) {
  throw SceneError((file.empty() ? std::string("<scene>") : file) + ": " + key + ": " + what);
}

}  // namespace

Camera resolve_camera(const CameraSettings& s, const Eigen::AlignedBox3d& bounds, double aspect,
                      const std::string& scene_file) {
  Camera c;
  c.up = s.up.normalized();
  c.fov_y_deg = s.fov_y_deg;
  c.near = s.near;
  c.far = s.far;
  const Vec3 centre = bounds.isEmpty() ? Vec3(Vec3::Zero()) : Vec3(bounds.center());
  c.target = s.target ? *s.target : centre;
  if (s.position) {
    c.position = *s.position;
  } else {
    // In front (-y, or -x when up is along y) and raised 30 degrees towards up.
    Vec3 front = -Vec3::UnitY();
    if (std::abs(front.dot(c.up)) > 0.9) front = -Vec3::UnitX();
    front = (front - front.dot(c.up) * c.up).normalized();
    const Vec3 dir = (front * std::cos(radians(30)) + c.up * std::sin(radians(30))).normalized();
    const double radius = bounds.isEmpty() ? 0.1 : 0.5 * bounds.diagonal().norm();
    const double half_y = 0.5 * radians(c.fov_y_deg);
    const double half_x = std::atan(aspect * std::tan(half_y));
    const double distance = 1.1 * radius / std::sin(std::min(half_x, half_y));
    c.position = c.target + distance * dir;
  }
  const Vec3 view = c.target - c.position;
  if (view.norm() == 0) {
    fail(scene_file, s.position ? "camera.position" : "camera.target",
         "the camera is at its target; allowed a position away from the target (by default the "
         "centre of the scene's bounding box)");
  }
  if (view.normalized().cross(c.up).norm() < 1e-6) {
    fail(scene_file, "camera.up",
         "the up vector is parallel to the viewing direction; allowed an up direction not "
         "parallel to target - position");
  }
  return c;
}

EyeView mono_eye(const Camera& camera, double aspect) {
  return stereo_eyes(camera, aspect, 0.0, 1.0)[0];
}

std::array<EyeView, 2> stereo_eyes(const Camera& camera, double aspect, double ipd,
                                   double focal_distance) {
  const Vec3 forward = camera.forward(), right = camera.right(), up = camera.true_up();
  const double n = camera.near;
  const double wd2 = n * std::tan(0.5 * radians(camera.fov_y_deg));
  const double shift = 0.5 * ipd * n / focal_distance;
  std::array<EyeView, 2> eyes;
  for (int e = 0; e < 2; ++e) {
    const double side = e == 0 ? -1.0 : 1.0;  // left eye at -IPD/2 along right
    EyeView& v = eyes[e];
    v.position = camera.position + side * 0.5 * ipd * right;
    v.view = look_along(v.position, right, up, forward);
    v.frustum.left = -aspect * wd2 - side * shift;
    v.frustum.right = aspect * wd2 - side * shift;
    v.frustum.bottom = -wd2;
    v.frustum.top = wd2;
    v.frustum.near = n;
    v.frustum.far = camera.far;
  }
  return eyes;
}

Eigen::Vector3d project_to_pixel(const EyeView& eye, const Vec3& world, double width,
                                 double height) {
  const Eigen::Vector4d p = eye.view * Eigen::Vector4d(world.x(), world.y(), world.z(), 1.0);
  const Frustum& f = eye.frustum;
  // The point on the near plane along the ray from the eye, then its place in the window.
  const double x_near = p.x() * f.near / -p.z();
  const double y_near = p.y() * f.near / -p.z();
  const double px = (x_near - f.left) / (f.right - f.left) * width;
  const double py = (f.top - y_near) / (f.top - f.bottom) * height;
  const double depth = (-p.z() - f.near) / (f.far - f.near);
  return {px, py, depth};
}

}  // namespace phyxel::render
