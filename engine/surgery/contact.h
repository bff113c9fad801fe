// Tool-tissue contact (DESIGN.md section 8), shared by the CPU reference (solver/cpu_solver)
// and mirrored by the GPU solver (compute/shaders/tool_contact.glsl): the broad phase through
// a rest-space hash grid, and the narrow phase and response of one phyxel.
//
// Response: projection of position and velocity (docs/decisions.md, "Contact"). After the
// drift of a substep, a phyxel inside a tool at the substep's end pose is moved to the tool's
// surface along the outward normal (dn = -phi n), and Coulomb friction removes its tangential
// motion relative to the tool surface (the tool's rigid motion carried the point from x_prev):
// all of it while |d_t| <= mu |dn| (sticking), else mu |dn| of it (sliding). The correction dx
// goes into u and dx/dt into v (so the velocity matches the new position, as the leapfrog's
// drift would have produced it), and the contact force on the phyxel is m dx / dt^2 (its
// momentum change over the substep, divided by dt). The tool feels the negative sum. Fixed and
// removed phyxels take no contact.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "engine/sampling/phyxel_set.h"
#include "engine/surgery/tool.h"

namespace phyxel {

// A tool as the solver sees it: shape and friction (pose comes per substep).
struct ContactTool {
  ToolShape shape;
  double friction = 0;
};
std::vector<ContactTool> contact_tools(const std::vector<ToolDesc>& tools);

// One substep's motion of one tool, from its pose at the substep's start to its end.
struct ToolMotion {
  ToolPose from, to;
};

// What one tool felt during one substep: the force on the tool (N, the negative sum of the
// contact forces on the phyxels) and the number of phyxels in contact.
struct ToolContactSample {
  Vec3 force = Vec3::Zero();
  uint32_t contacts = 0;
};

// The correction of one phyxel: x_new is its position after the drift, x_prev before it.
// Returns false (dx untouched) when the phyxel is outside the tool.
template <class Real>
bool contact_correction(const ContactTool& tool, const ToolMotion& motion,
                        const Eigen::Matrix<Real, 3, 1>& x_prev,
                        const Eigen::Matrix<Real, 3, 1>& x_new, Eigen::Matrix<Real, 3, 1>& dx);

// Broad phase: a counting-sort grid of the rest positions of every phyxel that can take
// contact (not fixed, not removed), cell size the largest support radius.
class ContactBroadPhase {
 public:
  explicit ContactBroadPhase(const PhyxelSet& set);
  // Phyxels (ascending) whose rest position lies in a cell that overlaps `bounds` grown by
  // `reach` (m). A phyxel whose current position is inside `bounds` is returned whenever its
  // displacement is below `reach`.
  std::vector<uint32_t> candidates(const Bounds& bounds, double reach) const;

 private:
  Vec3 origin_ = Vec3::Zero();
  double cell_ = 1;
  Eigen::Vector3i dims_{1, 1, 1};
  std::vector<uint32_t> cell_start_, sorted_;
};

// How far a phyxel can be from its rest position during a chunk of `duration` seconds that
// starts with largest displacement `max_u` and largest speed `max_v`: max_u + 2 duration max_v
// + the largest spacing. A heuristic bound (docs/decisions.md): the tool drives the tissue
// near it, and those phyxels are inside the tool's own swept bounds.
double contact_reach(double spacing, double max_u, double max_v, double duration);

// Union of the tools' bounds over a chunk's motions (substeps x tools, row-major).
Bounds swept_bounds(const std::vector<ContactTool>& tools, const std::vector<ToolMotion>& motion);

}  // namespace phyxel
