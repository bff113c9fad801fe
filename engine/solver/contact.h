// Tool-tissue contact (DESIGN.md section 8), shared by the CPU reference (solver/cpu_solver)
// and mirrored by the GPU solver (compute/shaders/tool_contact.glsl): the broad phase through
// a rest-space hash grid, and the narrow phase and response of one phyxel.
//
// Response: projection of position and velocity (docs/decisions.md, "Contact"). After the
// drift of a substep, a phyxel inside a tool at the substep's end pose (signed distance
// phi < 0, outward normal n) is corrected:
//  - position: moved to the surface, dn = -phi n, and its tangential slip relative to the
//    tool surface (whose rigid motion carried the point from x_prev) removed: all of it while
//    |slip| <= mu |dn| (sticking), else mu |dn| of it (sliding);
//  - velocity: relative to the tool surface's velocity, the normal part into the tool removed
//    (inelastic contact), and the tangential part reduced the same way within mu times that
//    normal change (Coulomb).
// The position correction carries no momentum; the velocity change does: the contact force on
// the phyxel is m dv / dt, and the tool feels the negative sum. A phyxel pushed deep into a
// tool (squeezed by its neighbours) is put back on the surface without being thrown: its
// speed after contact never exceeds the tool surface's by more than it had. Fixed and removed
// phyxels take no contact. A blade's point is sharp: with a threshold, the cap ahead of its tip
// holds nothing by friction (on_sharp_point); a phyxel the blade keeps on one side leaves its
// body toward that side (kept_side_exit).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <vector>

#include "engine/sampling/phyxel_set.h"
#include "engine/scene/tool_desc.h"

namespace phyxel {

// A tool as the solver sees it: shape and friction (pose comes per substep).
struct ContactTool {
  ToolShape shape;
  double friction = 0;
  Blade blade;      // a scalpel's (cuts() false for every other tool)
  Suction suction;  // an aspirator's (sucks() false for every other tool)
  Grasp grasp;      // a grasper's (grasps() false for every other tool)
};
std::vector<ContactTool> contact_tools(const std::vector<ToolDesc>& tools);

// One substep's motion of one tool, from its pose at the substep's start to its end.
struct ToolMotion {
  ToolPose from, to;
  bool suction_on = false;   // an aspirator sucks during the substep (Suction::on_at its middle)
  bool grip_closed = false;  // a grasper's jaws are closed in the substep (Grasp::closed_at)
};

// What one tool felt during one substep: the force on the tool (N, the negative sum of the
// contact forces on the phyxels), the number of phyxels in contact, and the range along the
// tool's axis from its tip at the substep's end pose (m; min > max where there is none) of the
// phyxels around it after the substep's contact: those in contact, and for a blade those within
// the largest object spacing of its surface (a blade thinner than the spacing touches few of
// the phyxels it passes between). It says how much of a blade is in the tissue
// (cut_feedback.h).
struct ToolContactSample {
  Vec3 force = Vec3::Zero();
  uint32_t contacts = 0;
  uint32_t held = 0;  // a grasper: the phyxels its jaws hold at the substep's end
  double axial_min = kNoContactAxial;
  double axial_max = -kNoContactAxial;
  static constexpr double kNoContactAxial = 1e30;
  void add_axial(double s) {
    axial_min = std::min(axial_min, s);
    axial_max = std::max(axial_max, s);
  }
};

// Whether x lies on a blade's point (docs/cutting.md, "The point"): a scalpel with a threshold,
// x ahead of its tip along the axis at the pose (the capsule's cap there). The cap stands in
// for a sharp point, which parts what it meets to either side: there contact takes no friction,
// so a phyxel met head-on slides off the cap within about a radius of advance instead of riding
// on it inside the friction cone. At threshold 0 the point cuts ahead in every substep; the
// cap keeps its friction.
bool on_sharp_point(const ContactTool& tool, const ToolPose& pose, const Vec3& x);

// The correction of one phyxel over a substep of dt: x_new is its position after the drift,
// x_prev before it, v its velocity. Returns false (dx, dv untouched) outside the tool.
// `keep`: for a phyxel a blade keeps on one side (cutting.h, side_entry), the blade's plane
// normal toward that side, else zero (kept_side_exit).
template <class Real>
bool contact_correction(const ContactTool& tool, const ToolMotion& motion, Real dt,
                        const Eigen::Matrix<Real, 3, 1>& x_prev,
                        const Eigen::Matrix<Real, 3, 1>& x_new, const Eigen::Matrix<Real, 3, 1>& v,
                        Eigen::Matrix<Real, 3, 1>& dx, Eigen::Matrix<Real, 3, 1>& dv,
                        const Vec3& keep = Vec3::Zero());

// A phyxel kept on one side (keep: the unit normal toward it) inside the blade's body beside
// its segment leaves the body toward that side, not radially: out along keep to the capsule's
// surface, without friction (the edge parts it, as the point does). Radially, a phyxel on the
// blade's plane ahead of it was pushed ahead of the body while its pairs held it to its side,
// until it snapped back (docs/cutting.md, "One side per phyxel"). Whether it applies; then
// `d` is that exit (distance < 0, normal keep).
bool kept_side_exit(const ContactTool& tool, const ToolPose& pose, const Vec3& x, const Vec3& keep,
                    ToolDistance& d);

// Broad phase of a chunk of substeps (CpuSolver::set_tool_motion; its GPU twin is
// compute/shaders/tool_broad_phase.comp): the entries of `list` (ascending phyxel indices: the
// solver's force list, moving phyxels of awake objects) that are neither fixed nor removed and
// whose current position rest + u lies inside `bounds` grown by `margin` (m). A non-finite
// margin (a diverging run) takes every such entry.
template <class Real>
std::vector<uint32_t> contact_candidates(const std::vector<uint32_t>& list,
                                         const std::vector<uint32_t>& flags,
                                         const std::vector<Eigen::Matrix<Real, 3, 1>>& rest,
                                         const std::vector<Eigen::Matrix<Real, 3, 1>>& u,
                                         const Bounds& bounds, double margin);

// How far outside the tools' swept bounds a phyxel that starts a chunk of `duration` seconds
// can still reach them: 2 duration max(max_v, tool_speed) + the largest spacing, with max_v the
// largest speed at the chunk's start and tool_speed the fastest any point of a tool moves in it
// (tissue the tool drives moves about as fast as the tool, and its neighbours follow). A
// heuristic bound (docs/decisions.md): the tool drives the tissue near it, and those phyxels
// are inside the tool's own swept bounds.
double contact_margin(double spacing, double max_v, double tool_speed, double duration);

// The fastest any point of a tool moves over a chunk's motions (substeps x tools, row-major;
// a capsule's far end counts its axis turning), m/s for substeps of dt.
double tool_speed(const std::vector<ContactTool>& tools, const std::vector<ToolMotion>& motion,
                  double dt);

// Union of the tools' bounds over a chunk's motions (substeps x tools, row-major).
Bounds swept_bounds(const std::vector<ContactTool>& tools, const std::vector<ToolMotion>& motion);
// The same over the tools with a blade (Blade::cuts): where the cut pass may sever, grown by the
// broad phase's margin (blades_sever_in_reach_only). Empty where no tool has one.
Bounds blade_swept_bounds(const std::vector<ContactTool>& tools,
                          const std::vector<ToolMotion>& motion);

}  // namespace phyxel
