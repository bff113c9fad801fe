#include "engine/geometry/tool.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace phyxel {
namespace {

// A unit vector perpendicular to the unit vector a, chosen by a fixed rule (the basis vector
// least aligned with a, crossed with a), so CPU and GPU pick the same one.
Vec3 perpendicular(const Vec3& a) {
  const Vec3 m = a.cwiseAbs();
  const Vec3 e = (m.x() <= m.y() && m.x() <= m.z()) ? Vec3::UnitX()
                 : (m.y() <= m.z())                 ? Vec3::UnitY()
                                                    : Vec3::UnitZ();
  return a.cross(e).normalized();
}

// The shortest rotation taking unit a to unit b.
Eigen::Matrix3d rotation_between(const Vec3& a, const Vec3& b) {
  const double c = std::clamp(a.dot(b), -1.0, 1.0);
  const Vec3 k = a.cross(b);
  const double s = k.norm();
  if (s < 1e-12) {
    if (c > 0) return Eigen::Matrix3d::Identity();
    return Eigen::AngleAxisd(M_PI, perpendicular(a)).toRotationMatrix();
  }
  return Eigen::AngleAxisd(std::atan2(s, c), k / s).toRotationMatrix();
}

}  // namespace

Vec3 slerp_axis(const Vec3& a, const Vec3& b, double s) {
  // The angle by atan2, as in rotation_between: acos(a.b) cannot resolve angles within about
  // 1.5e-8 of 0 or pi, so b = -a whose dot product rounds above -1 took the general branch,
  // where a + b = 0 gave a zero axis at s = 0.5 and a jump from a to -a instead of a turn.
  const double theta = std::atan2(a.cross(b).norm(), a.dot(b));
  if (theta < 1e-9) return a;
  if (M_PI - theta < 1e-9) {
    const Vec3 k = perpendicular(a);
    return std::cos(s * theta) * a + std::sin(s * theta) * k.cross(a);
  }
  const double st = std::sin(theta);
  return ((std::sin((1 - s) * theta) / st) * a + (std::sin(s * theta) / st) * b).normalized();
}

ToolPose pose_at(const std::vector<ToolKey>& path, double t) {
  ToolPose pose;
  if (path.empty()) return pose;
  if (t <= path.front().t) return {path.front().position, path.front().axis};
  if (t >= path.back().t) return {path.back().position, path.back().axis};
  const auto next = std::upper_bound(path.begin(), path.end(), t,
                                     [](double value, const ToolKey& k) { return value < k.t; });
  const ToolKey& b = *next;
  const ToolKey& a = *(next - 1);
  const double s = (t - a.t) / (b.t - a.t);
  pose.position = a.position + s * (b.position - a.position);
  pose.axis = slerp_axis(a.axis, b.axis, s);
  return pose;
}

ToolDistance tool_distance(const ToolShape& shape, const ToolPose& pose, const Vec3& x) {
  const double length = shape.type == ToolShape::Type::Capsule ? shape.length : 0.0;
  const Vec3 d = x - pose.position;
  const double along = std::clamp(d.dot(pose.axis), 0.0, length);
  const Vec3 off = d - along * pose.axis;
  const double r = off.norm();
  ToolDistance out;
  out.distance = r - shape.radius;
  if (r > 1e-12 * std::max(shape.radius, 1e-300)) {
    out.normal = off / r;
  } else {
    // On the segment itself (or the sphere's centre): push out sideways, by a fixed rule.
    out.normal = length > 0 ? perpendicular(pose.axis) : Vec3(-pose.axis);
  }
  return out;
}

Vec3 rotate_with_axis(const Vec3& from, const Vec3& to, const Vec3& v) {
  return rotation_between(from, to) * v;
}

Vec3 carry_point(const ToolPose& from, const ToolPose& to, const Vec3& x) {
  return to.position + rotation_between(from.axis, to.axis) * (x - from.position);
}

void Bounds::extend(const Bounds& b) {
  min = min.cwiseMin(b.min);
  max = max.cwiseMax(b.max);
}

void Bounds::grow(double by) {
  min.array() -= by;
  max.array() += by;
}

Bounds tool_bounds(const ToolShape& shape, const ToolPose& pose) {
  const double length = shape.type == ToolShape::Type::Capsule ? shape.length : 0.0;
  const Vec3 end = pose.position + length * pose.axis;
  Bounds b;
  b.min = pose.position.cwiseMin(end).array() - shape.radius;
  b.max = pose.position.cwiseMax(end).array() + shape.radius;
  return b;
}

}  // namespace phyxel
