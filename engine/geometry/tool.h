// Surgical tools' rigid shapes and poses (DESIGN.md section 8): the pose and distance math that
// the CPU reference, the GPU solver (compute/shaders/tool_contact.glsl mirrors it) and the
// renderer share. What a scene says of a tool (path, control, action) is in
// engine/scene/tool_desc.h.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "engine/geometry/vec3.h"

namespace phyxel {

// The tool's rigid shape, in the tool's frame: the tip at `position`, the shaft along `axis`.
struct ToolShape {
  enum class Type { Sphere, Capsule };
  Type type = Type::Sphere;
  double radius = 0;  // m (> 0)
  double length = 0;  // m, capsule only: the segment from the tip along the axis
};

// A keyframe of a tool's path: at time t (s) the tip is at `position`, the shaft along `axis`
// (a unit vector).
struct ToolKey {
  double t = 0;
  Vec3 position = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();
};

struct ToolPose {
  Vec3 position = Vec3::Zero();  // the tip, m
  Vec3 axis = Vec3::UnitZ();     // unit
};

// The pose of a path at time t: position interpolated linearly between keys, the axis by the
// shortest rotation (slerp of the unit vectors); before the first key the tool rests at it,
// after the last it stays there.
ToolPose pose_at(const std::vector<ToolKey>& path, double t);

// Unit vector along the shortest rotation from a to b (both unit) at fraction s in [0, 1].
// Opposite vectors rotate about an axis perpendicular to a, chosen deterministically.
Vec3 slerp_axis(const Vec3& a, const Vec3& b, double s);

// Signed distance from x to the tool's surface (negative inside) and the outward unit normal
// of the closest surface point. Where no direction is defined (a point on the capsule's
// segment, or the sphere's centre) the normal is fixed: a perpendicular to the capsule's axis,
// minus the axis for a sphere.
struct ToolDistance {
  double distance = 0;
  Vec3 normal = Vec3::UnitZ();
};
ToolDistance tool_distance(const ToolShape& shape, const ToolPose& pose, const Vec3& x);

// v turned by the shortest rotation that takes the unit axis `from` to the unit axis `to`.
Vec3 rotate_with_axis(const Vec3& from, const Vec3& to, const Vec3& v);

// The point the tool's motion from `from` to `to` carries x to (rigid motion: translation of
// the tip plus the shortest rotation of the axis about the tip).
Vec3 carry_point(const ToolPose& from, const ToolPose& to, const Vec3& x);

// Axis-aligned bounds of the tool's shape at a pose.
struct Bounds {
  Vec3 min = Vec3::Constant(1e300), max = Vec3::Constant(-1e300);
  void extend(const Bounds& b);
  void grow(double by);
  bool empty() const { return (min.array() > max.array()).any(); }
};
Bounds tool_bounds(const ToolShape& shape, const ToolPose& pose);

}  // namespace phyxel
