#include "engine/surgery/cut_feedback.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "engine/solver/cutting.h"

namespace phyxel {

CutFeedback cut_feedback(const Blade& blade, double mu, const ToolMotion& motion,
                         const ToolContactSample& sample) {
  CutFeedback f;
  if (!blade.cuts()) return f;
  const CutQuad quad = swept_quad(blade, motion.from, motion.to, 0);
  const Vec3& axis = motion.to.axis;
  f.cut_force = cut_force(sample.force, quad);
  const Vec3 n = axis.cross(quad.edge).normalized();
  const Vec3& fx = sample.force;
  const Vec3 fp = fx.dot(n) * n;
  const Vec3 fl = fx - fp;
  f.normal = fp.norm();
  f.in_plane = fl.norm();
  f.theta = std::atan2(f.in_plane, f.normal);
  if (sample.axial_min <= sample.axial_max) {
    const double low = std::clamp(sample.axial_min, 0.0, blade.length);
    const double high = std::clamp(sample.axial_max, 0.0, blade.length);
    f.depth = high - low;
  }
  // The faces slide along the blade middle's motion within the plane.
  const Vec3 mid_from = motion.from.position + 0.5 * blade.length * motion.from.axis;
  const Vec3 mid_to = motion.to.position + 0.5 * blade.length * axis;
  Vec3 slide = mid_to - mid_from;
  slide -= slide.dot(n) * n;
  const double moved = slide.norm();
  if (moved <= 1e-9 * blade.length) return f;
  const double drag = mu * (f.in_plane * f.depth / blade.length + f.normal);
  f.friction = -drag * slide / moved;
  return f;
}

}  // namespace phyxel
