// The aspirator (issue #11, docs/suction.md): its pull on the tissue, shared by the CPU reference
// (solver/cpu_solver.cpp apply_contacts) and mirrored by the GPU solver
// (compute/shaders/tool_contact.comp), and the paper's hybrid tearing at its mouth (section V.A,
// the fracture sphere), which the run loop applies between advances (engine/surgery/aspiration.h).
//
// Pull. While a suction tool is on, every phyxel (not fixed, not removed) within `reach` of its
// mouth, the tip, and ahead of it ((x - tip) . axis <= 0: the axis runs up the shaft) is pulled
// toward the tip by
//
//   f_i = 2 F V_i / V_reach (tip - x_i) / |tip - x_i|,   F = pressure pi radius^2,
//   V_reach = 2/3 pi reach^3 (the half ball ahead of the mouth),
//
// after the substep's contact correction, as a velocity change dt f_i / m_i, scaled by the
// tube's flow (suction_flow_factor)
//
//   max(0, 1 - w_i / flow_speed) min(1, flow_speed / (dt |f_i| / m_i)),
//   w_i = (v_i - v_tool) . (tip - x_i) / |tip - x_i|:
//
// tissue at rest relative to the tool feels the whole pull, tissue already moving into the
// mouth at the flow's speed none, and no substep takes w_i past the flow's speed, so torn
// fragments are drawn in at that speed instead of accelerating without bound (docs/suction.md,
// "Flow speed"). With the half ball
// full of tissue the pulls' vector sum is F along the axis, the pressure on the mouth's area
// (the mean of cos theta over a half ball is 1/2, hence the 2; their magnitudes add to 2 F);
// with less tissue in reach the tube pulls on what is there, so the force needs no sum over the
// phyxels (one pass, no reduction) and does not grow on a few phyxels as the tissue thins. The
// tool feels -sum f_i (docs/suction.md, "Why this law").
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <numbers>

#include "engine/solver/contact.h"

namespace phyxel {

// 2 F / V_reach (N/m^3): the pull per unit volume of tissue in reach, so that a full half ball's
// pulls add up to F along the axis; 0 for a tool that does not suck.
inline double suction_pull_density(const ContactTool& tool) {
  const Suction& s = tool.suction;
  if (!s.sucks() || !(s.reach > 0)) return 0;
  const double force = s.pressure * std::numbers::pi * tool.shape.radius * tool.shape.radius;
  return 2 * force / (2.0 / 3.0 * std::numbers::pi * s.reach * s.reach * s.reach);
}

// Whether x is in the mouth's reach at `pose`: within `reach` of the tip and ahead of it.
inline bool in_suction_reach(const ToolPose& pose, double reach, const Vec3& x) {
  const Vec3 r = x - pose.position;
  return r.squaredNorm() <= reach * reach && r.dot(pose.axis) <= 0;
}

// The flow's factor (see the top) of a phyxel moving at v_rel relative to the tool, with to_tip
// the unit vector from it to the tip and kick = dt |f_i| / m_i the whole pull's velocity change:
// 1 at rest relative to the tool when kick <= flow_speed.
template <class Real>
Real suction_flow_factor(const Suction& suction, const Eigen::Matrix<Real, 3, 1>& to_tip,
                         const Eigen::Matrix<Real, 3, 1>& v_rel, Real kick) {
  const Real flow = Real(suction.flow_speed);
  const Real w = v_rel.dot(to_tip);
  Real factor = Real(1) - w / flow;
  factor = factor > Real(0) ? (factor < Real(1) ? factor : Real(1)) : Real(0);
  return kick > flow ? factor * (flow / kick) : factor;
}

// f_i of a phyxel of volume `volume` at x at rest relative to the tool (zero outside the reach
// or at the tip itself); the flow's factor scales it (suction_flow_factor).
template <class Real>
Eigen::Matrix<Real, 3, 1> suction_pull(const ContactTool& tool, const ToolPose& pose,
                                       const Eigen::Matrix<Real, 3, 1>& x, Real volume) {
  using V3 = Eigen::Matrix<Real, 3, 1>;
  const Vec3 xd = x.template cast<double>();
  if (!tool.suction.sucks() || !in_suction_reach(pose, tool.suction.reach, xd)) return V3::Zero();
  const Vec3 to_tip = pose.position - xd;
  const double len = to_tip.norm();
  if (!(len > 0)) return V3::Zero();
  return (suction_pull_density(tool) * double(volume) / len * to_tip).template cast<Real>();
}

}  // namespace phyxel
