#include "engine/solver/contact.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numeric>

namespace phyxel {

std::vector<ContactTool> contact_tools(const std::vector<ToolDesc>& tools) {
  std::vector<ContactTool> out;
  for (const ToolDesc& t : tools) out.push_back({t.shape, t.friction, t.blade, t.suction, t.grasp});
  return out;
}

bool on_sharp_point(const ContactTool& tool, const ToolPose& pose, const Vec3& x) {
  return tool.blade.cuts() && tool.blade.threshold > 0 &&
         tool.shape.type == ToolShape::Type::Capsule && (x - pose.position).dot(pose.axis) < 0;
}

bool kept_side_exit(const ContactTool& tool, const ToolPose& pose, const Vec3& x, const Vec3& keep,
                    ToolDistance& d) {
  if (keep.isZero(0) || tool.shape.type != ToolShape::Type::Capsule) return false;
  const Vec3 r = x - pose.position;
  const double along = r.dot(pose.axis);
  if (!(along > 0 && along < tool.shape.length)) return false;  // the caps keep their normal
  const Vec3 off = r - along * pose.axis;
  const double b = off.dot(keep), a2 = off.squaredNorm() - b * b;
  const double exit = std::sqrt(std::max(0.0, tool.shape.radius * tool.shape.radius - a2)) - b;
  if (!(exit > 0)) return false;
  d.distance = -exit;
  d.normal = keep;
  return true;
}

template <class Real>
bool contact_correction(const ContactTool& tool, const ToolMotion& motion, Real dt,
                        const Eigen::Matrix<Real, 3, 1>& x_prev,
                        const Eigen::Matrix<Real, 3, 1>& x_new, const Eigen::Matrix<Real, 3, 1>& v,
                        Eigen::Matrix<Real, 3, 1>& dx, Eigen::Matrix<Real, 3, 1>& dv,
                        const Vec3& keep) {
  // The geometry in double from the Real inputs (exact), the corrections rounded to Real.
  const Vec3 xn = x_new.template cast<double>();
  ToolDistance d = tool_distance(tool.shape, motion.to, xn);
  if (!(d.distance < 0)) return false;
  const bool parted = kept_side_exit(tool, motion.to, xn, keep, d);
  const Vec3& n = d.normal;
  const double mu = parted || on_sharp_point(tool, motion.to, xn) ? 0.0 : tool.friction;
  // Position: out along the normal; the tangential slip relative to the tool surface (which
  // carried the point from x_prev) removed within the friction cone of the normal correction.
  const Vec3 dn = -d.distance * n;
  const Vec3 xp = x_prev.template cast<double>();
  const Vec3 carried = carry_point(motion.from, motion.to, xp) - xp;
  const Vec3 rel = xn + dn - xp - carried;
  const Vec3 slip = rel - rel.dot(n) * n;
  const double slip_norm = slip.norm(), slip_limit = mu * dn.norm();
  Vec3 dx_t = Vec3::Zero();
  if (slip_norm > 0) dx_t = -slip * std::min(1.0, slip_limit / slip_norm);
  // Velocity: the normal velocity into the tool (relative to the tool's surface velocity)
  // removed (inelastic), the tangential relative velocity removed within the friction cone
  // of that normal impulse.
  const Vec3 vr = v.template cast<double>() - carried / double(dt);
  const double vn = vr.dot(n);
  const Vec3 dv_n = vn < 0 ? Vec3(-vn * n) : Vec3::Zero();
  const Vec3 vt = vr - vn * n;
  const double vt_norm = vt.norm(), vt_limit = mu * dv_n.norm();
  Vec3 dv_t = Vec3::Zero();
  if (vt_norm > 0) dv_t = -vt * std::min(1.0, vt_limit / vt_norm);
  dx = (dn + dx_t).template cast<Real>();
  dv = (dv_n + dv_t).template cast<Real>();
  return true;
}

template bool contact_correction<double>(const ContactTool&, const ToolMotion&, double,
                                         const Eigen::Vector3d&, const Eigen::Vector3d&,
                                         const Eigen::Vector3d&, Eigen::Vector3d&, Eigen::Vector3d&,
                                         const Vec3&);
template bool contact_correction<float>(const ContactTool&, const ToolMotion&, float,
                                        const Eigen::Vector3f&, const Eigen::Vector3f&,
                                        const Eigen::Vector3f&, Eigen::Vector3f&, Eigen::Vector3f&,
                                        const Vec3&);

template <class Real>
std::vector<uint32_t> contact_candidates(const std::vector<uint32_t>& list,
                                         const std::vector<uint32_t>& flags,
                                         const std::vector<Eigen::Matrix<Real, 3, 1>>& rest,
                                         const std::vector<Eigen::Matrix<Real, 3, 1>>& u,
                                         const Bounds& bounds, double margin) {
  std::vector<uint32_t> out;
  if (bounds.empty()) return out;
  const bool all = !std::isfinite(margin);
  const Vec3 lo = bounds.min.array() - margin, hi = bounds.max.array() + margin;
  for (const uint32_t i : list) {
    if (flags[i] & (kFixed | kRemoved)) continue;
    const Vec3 x = (rest[i] + u[i]).template cast<double>();
    if (all || ((x.array() >= lo.array()).all() && (x.array() <= hi.array()).all()))
      out.push_back(i);
  }
  return out;
}
template std::vector<uint32_t> contact_candidates<double>(const std::vector<uint32_t>&,
                                                          const std::vector<uint32_t>&,
                                                          const std::vector<Eigen::Vector3d>&,
                                                          const std::vector<Eigen::Vector3d>&,
                                                          const Bounds&, double);
template std::vector<uint32_t> contact_candidates<float>(const std::vector<uint32_t>&,
                                                         const std::vector<uint32_t>&,
                                                         const std::vector<Eigen::Vector3f>&,
                                                         const std::vector<Eigen::Vector3f>&,
                                                         const Bounds&, double);

double contact_margin(double spacing, double max_v, double tool_speed, double duration) {
  return 2 * duration * std::max(max_v, tool_speed) + spacing;
}

double tool_speed(const std::vector<ContactTool>& tools, const std::vector<ToolMotion>& motion,
                  double dt) {
  double fastest = 0;
  for (size_t k = 0; k < motion.size() && !tools.empty() && dt > 0; ++k) {
    const ContactTool& t = tools[k % tools.size()];
    const double reach =
        t.shape.type == ToolShape::Type::Capsule ? t.shape.length : 0.0;  // the far end
    const ToolMotion& m = motion[k];
    const double travel = (m.to.position - m.from.position).norm() +
                          reach * (m.to.axis.normalized() - m.from.axis.normalized()).norm();
    fastest = std::max(fastest, travel / dt);
  }
  return fastest;
}

namespace {

// swept_bounds over the tools that `take` accepts.
template <class Take>
Bounds swept_bounds_of(const std::vector<ContactTool>& tools, const std::vector<ToolMotion>& motion,
                       Take take) {
  Bounds b;
  for (size_t k = 0; k < motion.size() && !tools.empty(); ++k) {
    const ContactTool& t = tools[k % tools.size()];
    if (!take(t)) continue;
    Bounds swept = tool_bounds(t.shape, motion[k].from);
    swept.extend(tool_bounds(t.shape, motion[k].to));
    if (t.suction.sucks()) swept.grow(t.suction.reach);  // what its mouth pulls on
    if (t.grasp.grasps()) swept.grow(t.grasp.reach);     // what its jaws close on
    b.extend(swept);
  }
  return b;
}

}  // namespace

Bounds swept_bounds(const std::vector<ContactTool>& tools, const std::vector<ToolMotion>& motion) {
  return swept_bounds_of(tools, motion, [](const ContactTool&) { return true; });
}

Bounds blade_swept_bounds(const std::vector<ContactTool>& tools,
                          const std::vector<ToolMotion>& motion) {
  return swept_bounds_of(tools, motion, [](const ContactTool& t) { return t.blade.cuts(); });
}

}  // namespace phyxel
