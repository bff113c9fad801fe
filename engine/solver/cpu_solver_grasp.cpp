// CpuSolver: the graspers (engine/solver/grasper.h; the GPU twin is compute/gpu_solver_grasp.cpp
// with compute/shaders/tool_grasp.comp). Called by apply_contacts after the contacts of a step,
// tool by tool: jaws that close capture the candidates within reach (ascending), closed jaws put
// what they hold where the tool carries it with the tool's velocity there and feel minus the
// momentum that took, per dt; jaws that open let go.
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/solver/cpu_solver.h"

namespace phyxel {

template <class Real>
void CpuSolver<Real>::apply_grasps(Real dt, const std::vector<ToolMotion>& now,
                                   std::vector<ToolContactSample>& felt) {
  for (size_t t = 0; t < tools_.size(); ++t) {
    const Grasp& grasp = tools_[t].grasp;
    Grip& grip = grips_[t];
    if (!grasp.grasps()) continue;
    if (!now[t].grip_closed) {  // open: let go
      grip.closed = false;
      grip.held.clear();
      continue;
    }
    if (!grip.closed) {  // closing: take what is within reach
      grip.closed = true;
      grip.held.clear();
      for (const uint32_t i : candidates_) {
        if (flags_[i] & (kFixed | kRemoved)) continue;
        const Vec3 x = rest_d_[i] + u_[i].template cast<double>();
        if (in_grasp_reach(now[t].to, grasp.reach, x))
          grip.held.push_back({i, grip_offset(now[t].to, x)});
      }
    }
    for (const GripEntry& e : grip.held) {
      const uint32_t i = e.phyxel;
      const GripTarget target = grip_target(now[t], e.offset, double(dt));
      const V3 v = target.velocity.template cast<Real>();
      const V3 f = mass_[i] * (v - v_[i]) / dt;
      u_[i] = (target.position - rest_d_[i]).template cast<Real>();
      v_[i] = v;
      contact_force_[i] += f;
      felt[t].force -= f.template cast<double>();
    }
    felt[t].held = static_cast<uint32_t>(grip.held.size());
  }
}

template <class Real>
void CpuSolver<Real>::restore_grips(const std::vector<Grip>& grips) {
  if (grips.size() != tools_.size())
    throw std::invalid_argument("restore_grips: " + std::to_string(grips.size()) + " grips for " +
                                std::to_string(tools_.size()) + " tools");
  for (const Grip& g : grips)
    for (const GripEntry& e : g.held)
      if (e.phyxel >= size())
        throw std::invalid_argument("restore_grips: no phyxel " + std::to_string(e.phyxel));
  grips_ = grips;
}

template void CpuSolver<double>::restore_grips(const std::vector<Grip>&);
template void CpuSolver<float>::restore_grips(const std::vector<Grip>&);
template void CpuSolver<double>::apply_grasps(double, const std::vector<ToolMotion>&,
                                              std::vector<ToolContactSample>&);
template void CpuSolver<float>::apply_grasps(float, const std::vector<ToolMotion>&,
                                             std::vector<ToolContactSample>&);

}  // namespace phyxel
