// Scalpel cutting (DESIGN.md section 8, docs/cutting.md): the blade, the surface it sweeps and
// the visibility criterion, shared by the CPU reference (solver/cpu_solver) and mirrored by the
// GPU solver (compute/shaders/tool_sever.comp).
//
// A scalpel's blade is the segment from the tool's tip along its axis, `length` long, whose
// sharp side faces `edge` (a unit vector perpendicular to the axis at the path's first key; it
// turns with the axis). In every substep in which the tissue presses the edge back with at least
// the tool's threshold (the force on the tool along -edge, N), the blade separates the tissue:
// every neighbour pair whose segment (current positions) crosses the quad the blade swept in
// that substep, reaching `reach` ahead of the edge at the substep's end, is severed on both sides
// for good. Below the threshold the blade only pushes (contact, like a probe).
//
// The crossing test is orientation-based with an explicit tie rule: an endpoint on the quad's
// plane counts as on its positive side, and a segment through a triangle's edge or vertex
// crosses it, except through the cut's front (blade_severs). It is evaluated in the pair's
// canonical order (lower index first), so both sides of a pair reach the same decision. In float
// (GPU) and double (CPU) decisions can differ only for pairs with an endpoint within
// kCutTieTolerance of the plane of a swept triangle or passing within it of a triangle's edge.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "engine/scene/tool_desc.h"
#include "engine/solver/contact.h"

namespace phyxel {

// The documented float-against-double band of the crossing test (m): CPU and GPU may decide a
// pair differently only when it passes this close to a swept triangle's plane or edge.
inline constexpr double kCutTieTolerance = 1e-6;

// The edge direction at a pose: `edge` turned by the shortest rotation from the reference axis
// to the pose's axis.
Vec3 blade_edge(const Blade& blade, const ToolPose& pose);

// The quad the blade swept over one substep's motion, as corners p0..p3 (triangles p0 p1 p2 and
// p0 p2 p3): p0, p1 the blade's tip and end at the start pose; p2, p3 its end and tip at the
// end pose, moved ahead along the edge there by `reach` (each end in proportion to its motion
// along the edge over the faster end's: a turned blade reaches nothing ahead at its pivot). The
// edge of a substep is the direction the blade's middle moves across its axis (it cuts the way it
// is pushed, its back too), or blade_edge where it does not move sideways (a stab).
struct CutQuad {
  std::array<Vec3, 4> corner;
  Vec3 edge = Vec3::UnitX();            // the edge direction at the end pose
  bool sideways = false;                // the edge is the blade's sideways motion (not a stab)
  double tip_moved = 0, end_moved = 0;  // m: the tip's and the end's motion along the edge
};
CutQuad swept_quad(const Blade& blade, const ToolPose& from, const ToolPose& to, double reach);
// How far ahead a blade's quad reaches: its own reach, else the object's spacing.
double blade_reach(const Blade& blade, double spacing);

// Whether the blade advances in a substep from `from` to `to`: it moves across its axis (the
// quad's edge is its motion), or along it tip first (a stab: against the axis, which runs from
// the tip to the handle). A blade that stops or is drawn back along its axis does not (the
// cutting state ends; docs/cutting.md, "Rupture and the cutting state").
bool blade_advances(const CutQuad& quad, const ToolPose& from, const ToolPose& to);

// The force pressing the edge into the tissue for a force `on_tool` (N) felt by the tool: its
// component against the edge, max(0, -on_tool . edge).
double edge_force(const Vec3& on_tool, const Vec3& edge);

// The force with which the blade cuts in a substep, compared with the threshold: the larger of
// the edge force and the force pressing the point in (a stab along the blade: on_tool . axis,
// the axis at the quad's start pose, from p0 to p1).
double cut_force(const Vec3& on_tool, const CutQuad& quad);

// Whether the segment p -> q crosses triangle a b c (tie rule above). `t` gets the crossing's
// fraction along p -> q when it does.
template <class Real>
bool segment_crosses_triangle(const Eigen::Matrix<Real, 3, 1>& p,
                              const Eigen::Matrix<Real, 3, 1>& q,
                              const Eigen::Matrix<Real, 3, 1>& a,
                              const Eigen::Matrix<Real, 3, 1>& b,
                              const Eigen::Matrix<Real, 3, 1>& c, Real* t = nullptr);

// Whether the segment crosses the quad (either triangle); t as above.
template <class Real>
bool segment_crosses_quad(const Eigen::Matrix<Real, 3, 1>& p, const Eigen::Matrix<Real, 3, 1>& q,
                          const std::array<Eigen::Matrix<Real, 3, 1>, 4>& quad, Real* t = nullptr);

// Whether the blade severs the segment: it crosses the quad (or the body's strip, same corner
// order), but not within kCutTieTolerance of the line p0 -> p3 that the blade's tip swept, the
// cut's front. A pair through the front passes the crack's edge, not the crack: the tie rule
// alone cut such pairs by rounding (half of the diagonals under a front half-way between
// lattice planes; docs/cutting.md, "Stiffness of a cut body").
template <class Real>
bool blade_severs(const Eigen::Matrix<Real, 3, 1>& p, const Eigen::Matrix<Real, 3, 1>& q,
                  const std::array<Eigen::Matrix<Real, 3, 1>, 4>& quad, Real* t = nullptr);

// How close (m) the segment p -> q comes to a tie of the crossing test against the quad: the
// smallest of the endpoints' distances to each triangle's plane and of the distances from the
// segment's plane crossing to each triangle's edges. Pairs below kCutTieTolerance are the ones
// CPU and GPU may decide differently.
double crossing_tie_distance(const Vec3& p, const Vec3& q, const std::array<Vec3, 4>& quad);

// The edge's resistance (docs/cutting.md, "The edge's resistance"): a blade with a threshold
// that moves sideways is held back by the live pairs its edge has passed. In a stab (no sideways
// motion, the tip leading) the point is, in the same frame turned: its "blade" the body's width
// across the blade's plane (axis = the blade's edge, length 2 radius), its "edge" -axis, its front
// the tip's cap, so the pairs the point has passed through push the tissue ahead of it. A pair (i,
// j) whose segment crosses the blade's plane (axis and edge at the substep's end pose) within the
// blade's length, delta behind the front of its body (0 < delta <= depth; the front lies the
// body's radius ahead of the axis; behind against that point's motion), is pushed ahead along
// its motion with stiffness * a_ij * delta
// (split (1 - t) on i, t on j), a_ij its share of the plane's area (pair_area_share). The tool
// feels the sum back; once its cutting force reaches the threshold, the held pairs are severed
// with those the blade swept. A pair carried past depth is severed whatever the force
// (edge_passes).
struct EdgeFrame {
  Vec3 tip = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();
  Vec3 edge = Vec3::UnitX();
  Vec3 normal = Vec3::UnitY();            // axis x edge
  double length = 0;                      // m: the blade's
  double front = 0;                       // m: the body's radius
  double depth = 0;                       // m: how far behind the front a pair is still held
  double stiffness = 0;                   // N/m^3; 0: nothing is held (a stab, or threshold 0)
  double tip_motion = 0, end_motion = 0;  // m along the edge (CutQuad's tip_moved, end_moved)
};
EdgeFrame edge_frame(const Blade& blade, const CutQuad& quad, const ToolPose& to, double radius,
                     double depth);

// Whether the edge holds the pair p -> q (canonical order); t: the crossing's fraction along
// p -> q, delta: how far behind the front it lies (m), direction: +1 or -1, the way the blade
// moves along the edge where the pair crosses (a blade turned about a point of its own moves
// backwards beyond it: "behind" is against each point's own motion).
bool edge_holds(const Vec3& p, const Vec3& q, const EdgeFrame& f, double* t, double* delta,
                double* direction);

// Whether the edge pushes the held pair p -> q (canonical order), as edge_holds within a band
// depth * |m| / max(|m_tip|, |m_end|) deep, m the blade's motion along the edge where the pair
// crosses: a turned blade pushes nothing at its pivot, which passes nothing (there the full
// k a delta, one way on each side of the pivot, was a field with a curl that threw a phyxel
// beside it; docs/cutting.md, "Nothing pushed at a pivot"). Severing still takes edge_holds.
bool edge_pushes(const Vec3& p, const Vec3& q, const EdgeFrame& f, double* t, double* delta,
                 double* direction);

// Whether the edge carries the pair p -> q (canonical order) past its reach in this substep: it
// crosses the blade's plane as for edge_holds, more than depth and at most depth plus the
// blade's motion there behind the front (held at the substep's start, let go at its end). Such a
// pair is severed whatever the cutting force (docs/cutting.md, "The edge's resistance"): the
// edge is not a hook that drags a strand along. t: where it crosses the blade's plane.
bool edge_passes(const Vec3& p, const Vec3& q, const EdgeFrame& f, double* t);

// The edge's push on one phyxel, bounded by the blade's threshold (docs/cutting.md, "The edge's
// resistance"): pairs that alone would push a phyxel harder than the whole blade's threshold
// fail in this substep, so they carry at most that force while they do (a blade that meets
// pairs already behind it, after a stab, would otherwise throw the phyxel at omega * delta).
Vec3 bounded_edge_push(const Vec3& force, double threshold);

// A pair's share of the area of a plane with unit normal n: (V_i + V_j) / (S_i + S_j), with
// S = half the sum over a phyxel's neighbours of |(x_k - x_i) . n| (the pairs a unit area of
// the plane crosses, times the volume, on a regular lattice), so the shares of the pairs
// crossing any part of the plane add up to its area whatever the spacing.
double pair_area_share(double volume_sum, double s_sum);

// How far beyond a tool's swept bounds the contact broad phase looks (before the motion's
// margin): the object spacing, and where a tool cuts, a support radius beyond the farther of
// it and the blades' reach (the pairs a blade's quad or edge reaches, both ends).
double cut_candidate_reach(const std::vector<ContactTool>& tools, double spacing, double support);

// Whether a chunk's cut pass tests no pair where no broad-phase candidate lies within the
// blades' swept bounds (blade_swept_bounds) grown by the broad phase's margin: where every
// blade cuts at threshold 0. A blade with a threshold keeps its candidates' sides (and its edge
// resists) in every substep, so its pass takes every candidate.
bool blades_sever_in_reach_only(const std::vector<ContactTool>& tools);

// One side per phyxel while a blade passes (docs/cutting.md, "One side per phyxel"). Each blade
// with a threshold above 0 keeps, per phyxel, the side of its plane (n = axis x edge at the
// substep's end pose) the phyxel was first cut to: kSidePlus where the partner it was cut from lay
// at -n (n . (x_i - x_j) >= 0), kSideMinus the other way. A pair is neither held nor severed when
// it would cut a phyxel from the side it was kept on (a phyxel on the blade's plane, pushed across
// it, would otherwise lose its pairs to both sides). A side is kept while the phyxel stays a
// candidate of the broad phase in every substep; a phyxel cut to both sides in one substep gets
// none.
//
// Entry per blade and phyxel: pass << 4 | side at the pass's start << 2 | side after it, `pass`
// the substep's count (modulo 2^28; CpuSolver::cut_pass_, the GPU's pass). Written by the
// phyxel's own candidate during its pass; read by any, which gives the side at the pass's start
// whether the writer has run yet or not (the GPU's threads need no order).
inline constexpr uint32_t kSideNone = 0, kSidePlus = 1, kSideMinus = 2;
inline constexpr uint32_t kSidePassMask = (1u << 28) - 1;
uint32_t side_at_start(uint32_t entry, uint32_t pass);  // a side entry's side for pass `pass`
uint32_t side_entry(uint32_t pass, uint32_t start, uint32_t after);
// The side the pass leaves: the one kept, else the one the pass cut to (`cut`: the kSidePlus and
// kSideMinus bits of the pairs it cut), else none.
uint32_t side_after(uint32_t start, uint32_t cut);
// The side of x_i from x_j across the plane with normal n (n . (x_i - x_j) >= 0: plus).
uint32_t side_from(const Vec3& normal, const Vec3& xi, const Vec3& xj);
// Whether a pair crossing the blade may be cut (or held) given its phyxels' kept sides.
bool sides_allow(uint32_t side_i, uint32_t side_j, const Vec3& normal, const Vec3& xi,
                 const Vec3& xj);

// The kept side that holds for a phyxel at x. A side lapses where the phyxel lies on the other
// side of the blade's plane (f.normal through f.tip) farther than `band` (side_band), or where
// the blade's plane has turned from the one the side was learned on (`learned`: its normal,
// pack_side_normal) by more than kSideTurn. A blade turned about a point of its own keeps the
// phyxels near it candidates all the turn, and a side learned at one angle is the wrong one
// later; position alone cannot tell a plane that turned under a phyxel from a phyxel drifting
// across a plane that stayed (docs/cutting.md, "Stale sides at the cone's apex"). A lapse
// leaves no side for the rest of that substep (side_after_lapse): the learned normal is written
// only in a substep that starts without a side, when no reader needs it.
uint32_t side_near_plane(uint32_t side, uint32_t learned, const EdgeFrame& f, const Vec3& x,
                         double band);
// That band: a lattice spacing (where the next row of phyxels lies), at least the body's radius.
// The body's radius alone let phyxels on the plane of scalpel_cut's block drift past it and be
// cut from both sides (BladeSide.ACutAlongALatticePlaneAboveItsThresholdFreesNoPhyxel).
double side_band(double body_radius, double spacing);
// How far the blade's plane may turn from the one a side was learned on (rad) before the side
// lapses; the GPU's twin is blade_edge.glsl's kSideTurnCos.
inline constexpr double kSideTurn = 0.17453292519943295;  // 10 degrees
// A unit normal in one word (octahedral, two 16-bit signed fractions; blade_edge.glsl's twin).
uint32_t pack_side_normal(const Vec3& n);
Vec3 unpack_side_normal(uint32_t word);
// The side a pass leaves (side_after), none where the side at its start lapsed in it.
uint32_t side_after_lapse(uint32_t start, uint32_t held, uint32_t cut);

// A phyxel's kept side for one blade (checkpoints, tests): kSidePlus or kSideMinus.
struct BladeSide {
  uint32_t phyxel = 0;
  uint32_t side = kSideNone;
  uint32_t normal = 0;  // pack_side_normal of the plane it was learned on
};

// One severed pair (i < j): where the blade crossed it, as the fraction t along x_i -> x_j.
// A pair torn apart by its stress (engine/solver/tearing.h) has t = 0.5 and `torn` set.
struct SeveredPair {
  uint32_t i = 0, j = 0;
  float t = 0.5f;
  bool torn = false;
};

}  // namespace phyxel
