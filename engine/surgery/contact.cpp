#include "engine/surgery/contact.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numeric>

namespace phyxel {

std::vector<ContactTool> contact_tools(const std::vector<ToolDesc>& tools) {
  std::vector<ContactTool> out;
  for (const ToolDesc& t : tools) out.push_back({t.shape, t.friction});
  return out;
}

template <class Real>
bool contact_correction(const ContactTool& tool, const ToolMotion& motion, Real dt,
                        const Eigen::Matrix<Real, 3, 1>& x_prev,
                        const Eigen::Matrix<Real, 3, 1>& x_new, const Eigen::Matrix<Real, 3, 1>& v,
                        Eigen::Matrix<Real, 3, 1>& dx, Eigen::Matrix<Real, 3, 1>& dv) {
  // The geometry in double from the Real inputs (exact), the corrections rounded to Real.
  const Vec3 xn = x_new.template cast<double>();
  const ToolDistance d = tool_distance(tool.shape, motion.to, xn);
  if (!(d.distance < 0)) return false;
  const Vec3& n = d.normal;
  const double mu = tool.friction;
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
                                         const Eigen::Vector3d&, Eigen::Vector3d&,
                                         Eigen::Vector3d&);
template bool contact_correction<float>(const ContactTool&, const ToolMotion&, float,
                                        const Eigen::Vector3f&, const Eigen::Vector3f&,
                                        const Eigen::Vector3f&, Eigen::Vector3f&, Eigen::Vector3f&);

ContactBroadPhase::ContactBroadPhase(const PhyxelSet& set) {
  std::vector<uint32_t> members;
  Eigen::AlignedBox3d box;
  for (size_t i = 0; i < set.size(); ++i) {
    if (set.flags[i] & (kFixed | kRemoved)) continue;
    members.push_back(static_cast<uint32_t>(i));
    box.extend(set.rest[i]);
  }
  cell_ = 0;
  for (const ObjectRange& o : set.objects) cell_ = std::max(cell_, o.support_radius);
  if (members.empty() || !(cell_ > 0)) {
    cell_start_.assign(2, 0);
    return;
  }
  origin_ = box.min();
  for (int a = 0; a < 3; ++a)
    dims_[a] = std::max(1, static_cast<int>(std::floor(box.sizes()[a] / cell_)) + 1);
  const size_t cells = size_t(dims_.x()) * dims_.y() * dims_.z();
  auto key = [&](const Vec3& p) {
    size_t k = 0;
    for (int a = 2; a >= 0; --a) {
      const int c =
          std::clamp(static_cast<int>(std::floor((p[a] - origin_[a]) / cell_)), 0, dims_[a] - 1);
      k = k * dims_[a] + c;
    }
    return k;
  };
  cell_start_.assign(cells + 1, 0);
  for (uint32_t i : members) ++cell_start_[key(set.rest[i]) + 1];
  std::partial_sum(cell_start_.begin(), cell_start_.end(), cell_start_.begin());
  sorted_.resize(members.size());
  std::vector<uint32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (uint32_t i : members) sorted_[fill[key(set.rest[i])]++] = i;
}

std::vector<uint32_t> ContactBroadPhase::candidates(const Bounds& bounds, double reach) const {
  std::vector<uint32_t> out;
  if (sorted_.empty() || bounds.empty()) return out;
  Eigen::Vector3i lo, hi;
  for (int a = 0; a < 3; ++a) {
    const double l = (bounds.min[a] - reach - origin_[a]) / cell_;
    const double h = (bounds.max[a] + reach - origin_[a]) / cell_;
    if (h < 0 || l >= dims_[a]) return out;  // the grown box misses the grid
    lo[a] = std::clamp(static_cast<int>(std::floor(l)), 0, dims_[a] - 1);
    hi[a] = std::clamp(static_cast<int>(std::floor(h)), 0, dims_[a] - 1);
  }
  for (int z = lo.z(); z <= hi.z(); ++z)
    for (int y = lo.y(); y <= hi.y(); ++y)
      for (int x = lo.x(); x <= hi.x(); ++x) {
        const size_t k = (size_t(z) * dims_.y() + y) * dims_.x() + x;
        out.insert(out.end(), sorted_.begin() + cell_start_[k],
                   sorted_.begin() + cell_start_[k + 1]);
      }
  std::sort(out.begin(), out.end());
  return out;
}

double contact_reach(double spacing, double max_u, double max_v, double duration) {
  return max_u + 2 * duration * max_v + spacing;
}

Bounds swept_bounds(const std::vector<ContactTool>& tools, const std::vector<ToolMotion>& motion) {
  Bounds b;
  for (size_t k = 0; k < motion.size() && !tools.empty(); ++k) {
    const ContactTool& t = tools[k % tools.size()];
    b.extend(tool_bounds(t.shape, motion[k].from));
    b.extend(tool_bounds(t.shape, motion[k].to));
  }
  return b;
}

}  // namespace phyxel
