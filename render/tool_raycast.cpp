#include "render/tool_raycast.h"

#include <cmath>
#include <limits>

namespace phyxel::render {
namespace {

constexpr double kMiss = std::numeric_limits<double>::infinity();

// As ball_entry in tool_common.glsl: keeps the entry of the ray into the ball (c, r) when it
// is nearer than best.t and in front of the origin.
void ball_entry(const Vec3& o, const Vec3& dir, const Vec3& c, double r, ToolRayHit& best) {
  const Vec3 w = c - o;
  const double b = dir.dot(w);
  const Vec3 q = w - b * dir;
  const double h = r * r - q.squaredNorm();
  if (h < 0) return;
  const double t = b - std::sqrt(h);
  if (t > 0 && t < best.t) {
    best.t = t;
    best.normal = (o + t * dir - c) / r;
  }
}

// As cylinder_entry: the side of the cylinder around [p0, p0 + len a].
void cylinder_entry(const Vec3& o, const Vec3& dir, const Vec3& p0, const Vec3& a, double len,
                    double r, ToolRayHit& best) {
  const Vec3 w = o - p0;
  const Vec3 d_perp = dir - dir.dot(a) * a;
  const Vec3 w_perp = w - w.dot(a) * a;
  const double A = d_perp.squaredNorm();
  if (!(A > 1e-12)) return;
  const double h = A * r * r - d_perp.cross(w_perp).squaredNorm();
  if (h < 0) return;
  const double t = (-w_perp.dot(d_perp) - std::sqrt(h)) / A;
  const Vec3 x = o + t * dir;
  const double y = (x - p0).dot(a);
  if (t > 0 && t < best.t && y >= 0 && y <= len) {
    best.t = t;
    best.normal = (x - p0 - y * a) / r;
  }
}

}  // namespace

std::vector<ToolDrawable> tool_drawables(const std::vector<ToolDesc>& tools, double t) {
  std::vector<ToolDrawable> out;
  out.reserve(tools.size());
  for (const ToolDesc& tool : tools)
    out.push_back({tool.shape, pose_at(tool.path, tool.cycle_time(t))});
  return out;
}

ToolRayHit intersect_tool(const ToolShape& shape, const ToolPose& pose, const Vec3& origin,
                          const Vec3& dir) {
  ToolRayHit best;
  best.t = kMiss;
  const double len = shape.type == ToolShape::Type::Capsule ? shape.length : 0.0;
  ball_entry(origin, dir, pose.position, shape.radius, best);
  if (len > 0) {
    ball_entry(origin, dir, pose.position + len * pose.axis, shape.radius, best);
    cylinder_entry(origin, dir, pose.position, pose.axis, len, shape.radius, best);
  }
  best.hit = best.t < kMiss;
  if (!best.hit) best.t = 0;
  return best;
}

ToolPixel tool_at_pixel(const EyeView& eye, uint32_t width, uint32_t height,
                        const std::vector<ToolDrawable>& tools, uint32_t x, uint32_t y) {
  const Frustum& f = eye.frustum;
  // pixel_ray of splat_common.glsl: through the pixel's centre on the near plane.
  const double ax = (x + 0.5) / width, ay = (y + 0.5) / height;
  const Vec3 dir =
      Vec3(f.left + ax * (f.right - f.left), f.top + ay * (f.bottom - f.top), -f.near).normalized();
  const Eigen::Matrix3d rot = eye.view.topLeftCorner<3, 3>();
  const Vec3 shift = eye.view.topRightCorner<3, 1>();
  ToolPixel best;
  best.depth = 2;
  for (size_t k = 0; k < tools.size(); ++k) {
    ToolPose pose;
    pose.position = rot * tools[k].pose.position + shift;
    pose.axis = rot * tools[k].pose.axis;
    const ToolRayHit h = intersect_tool(tools[k].shape, pose, Vec3::Zero(), dir);
    if (!h.hit) continue;
    const double d = (h.t * -dir.z() - f.near) / (f.far - f.near);
    if (d >= 0 && d <= 1 && d < best.depth) {
      best.tool = static_cast<int>(k);
      best.depth = d;
      best.normal = h.normal;
    }
  }
  if (best.tool < 0) best.depth = 1;
  return best;
}

}  // namespace phyxel::render
