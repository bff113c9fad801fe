// Surgical tools (DESIGN.md section 8): one model for every instrument. A tool is a rigid
// shape, a pose over time (a path of keyframes, or a haptic device) and an action. This header
// is the data of the scene model plus the pose and distance math that the CPU reference, the
// GPU solver (compute/shaders/tool_contact.glsl mirrors it) and the renderer share.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace phyxel {

using Vec3 = Eigen::Vector3d;

// The cutting part of a tool (ToolDesc::blade, ContactTool::blade; engine/surgery/cutting.h).
struct Blade {
  double length = 0;                    // m, from the tip along the axis (> 0: the tool cuts)
  Vec3 edge = Vec3::UnitX();            // unit, perpendicular to the axis at the first key
  Vec3 reference_axis = Vec3::UnitZ();  // the axis at the path's first key
  double threshold = 0;                 // N: the edge force at which the tissue separates
  double reach = 0;                     // m: how far ahead of the edge it separates
  bool cuts() const { return length > 0; }
};

// The action of an aspirator (ToolDesc::suction, ContactTool::suction; engine/surgery/suction.h):
// while on, its mouth (the tip) pulls the phyxels within `reach` ahead of it toward itself,
// `pressure` times the mouth's area (pi radius^2) in all when the reach is full of tissue.
struct Suction {
  double pressure = 0;  // Pa (> 0: the tool sucks)
  double reach = 0;     // m, from the tip
  double from = 0;      // s: on during [from, until)
  double until = std::numeric_limits<double>::infinity();
  bool sucks() const { return pressure > 0; }
  bool on_at(double t) const { return sucks() && from <= t && t < until; }
};

// The action of a grasper (ToolDesc::grasp, ContactTool::grasp; engine/surgery/grasper.h): its
// jaws close at `from` on every phyxel within `reach` of its tip and carry them rigidly with
// the tool until `until`, when they let go.
struct Grasp {
  double reach = 0;  // m, from the tip (> 0: the tool grasps)
  double from = 0;   // s: closed during [from, until)
  double until = std::numeric_limits<double>::infinity();
  bool grasps() const { return reach > 0; }
  bool closed_at(double t) const { return grasps() && from <= t && t < until; }
};

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

// Virtual coupling between a haptic device and the simulated tool (engine/surgery/haptic_loop.h).
struct CouplingSettings {
  double stiffness = 200;  // N/m, spring between the device pose and the simulated tool
  double damping = 0;      // N s/m; 0: critical for `mass`
  double mass = 0.02;      // kg, the simulated tool's mass in the haptic loop
  double max_force = 8;    // N, the force sent to the hand is clamped to this
};

struct ToolDesc {
  enum class Type { Probe, Scalpel, Suction, Grasper };
  enum class Control { Path, Haptic };
  std::string name;
  Type type = Type::Probe;
  ToolShape shape;
  std::vector<ToolKey> path;  // strictly increasing t; at least one key
  double friction = 0;        // Coulomb coefficient mu (>= 0)
  Control control = Control::Path;
  CouplingSettings coupling;  // control haptic only
  Blade blade;                // scalpel only (engine/surgery/cutting.h)
  Suction suction;            // suction only (engine/surgery/suction.h)
  Grasp grasp;                // grasper only (engine/surgery/grasper.h)
  // A scripted cycle: the path and the suction and grasp windows repeat every `repeat` s (0:
  // once); the tool at t does what it did at t mod repeat (the path ends where it began).
  double repeat = 0;
  double cycle_time(double t) const { return repeat > 0 ? std::fmod(t, repeat) : t; }
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
