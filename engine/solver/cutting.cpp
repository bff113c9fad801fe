#include "engine/solver/cutting.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

namespace phyxel {

Vec3 blade_edge(const Blade& blade, const ToolPose& pose) {
  return rotate_with_axis(blade.reference_axis, pose.axis, blade.edge);
}

double blade_reach(const Blade& blade, double spacing) {
  return blade.reach > 0 ? blade.reach : spacing;
}

CutQuad swept_quad(const Blade& blade, const ToolPose& from, const ToolPose& to, double reach) {
  CutQuad q;
  q.edge = blade_edge(blade, to);
  // The blade cuts the way it moves: the edge of a substep is the sideways motion of the
  // blade's middle; `edge` (turned with the axis) orients only a blade that does not move
  // sideways (a stab along its axis). The turned `edge` cannot stand for the motion: on a path
  // that turns the axis around another axis (a conical cut) the shortest rotation from the
  // first key's axis turns it against the motion over half the turn.
  const Vec3 mid_from = from.position + 0.5 * blade.length * from.axis;
  const Vec3 mid_to = to.position + 0.5 * blade.length * to.axis;
  Vec3 side = mid_to - mid_from;
  side -= side.dot(to.axis) * to.axis;
  const double moved = side.norm();
  q.sideways = moved > 1e-9 * std::max(blade.length, 1e-12);
  if (q.sideways) q.edge = side / moved;
  // Each end of the blade reaches ahead by `reach` times its motion along the edge over the
  // faster end's: a blade moved straight reaches `reach` ahead at both ends; a blade turned
  // about a point of its own reaches ahead in proportion to the distance from that pivot, and
  // not at all at the pivot (which would otherwise cut a disc around itself).
  const Vec3 end_from = from.position + blade.length * from.axis;
  const Vec3 end_to = to.position + blade.length * to.axis;
  const double tip_moved = (to.position - from.position).dot(q.edge);
  const double end_moved = (end_to - end_from).dot(q.edge);
  const double fastest = std::max(std::abs(tip_moved), std::abs(end_moved));
  auto ahead = [&](double moved) {
    return Vec3((fastest > 0 ? reach * moved / fastest : reach) * q.edge);
  };
  q.tip_moved = tip_moved;
  q.end_moved = end_moved;
  q.corner[0] = from.position;
  q.corner[1] = end_from;
  q.corner[2] = end_to + ahead(end_moved);
  q.corner[3] = to.position + ahead(tip_moved);
  return q;
}

EdgeFrame edge_frame(const Blade& blade, const CutQuad& quad, const ToolPose& to, double radius,
                     double depth) {
  EdgeFrame f;
  f.tip = to.position;
  f.axis = to.axis;
  f.edge = quad.edge;
  f.normal = to.axis.cross(quad.edge).normalized();
  f.length = blade.length;
  f.front = radius;
  f.depth = depth;
  f.stiffness = blade.threshold > 0 && quad.sideways ? blade.stiffness : 0.0;
  f.tip_motion = quad.tip_moved;
  f.end_motion = quad.end_moved;
  if (quad.sideways) return f;
  // A stab: the point's frame. The body's width across the blade's plane is the "blade", its
  // tip the front, pushed along -axis; the plane (its normal) is the same.
  const double advance = (quad.corner[0] - to.position).dot(to.axis);
  f.tip = to.position - radius * quad.edge;
  f.axis = quad.edge;
  f.edge = -to.axis;
  f.length = 2 * radius;
  f.stiffness = blade.threshold > 0 && advance > 0 && radius > 0 ? blade.stiffness : 0.0;
  f.tip_motion = f.end_motion = advance;
  return f;
}

namespace {

// Where the pair p -> q crosses the blade's plane within its length (edge_holds, edge_passes):
// its fraction t, how far behind the body's front against the blade's motion there, and that
// motion (m along the edge; linear from the tip's to the end's). False where the segment does
// not cross, or the blade does not move there.
struct EdgeCrossing {
  double t = 0, behind = 0, moved = 0;
};

// The depth of the band that pushes at that point: depth times that point's motion along the
// edge over the faster end's, as the quad's reach ahead (a turned blade pushes nothing at its
// pivot, where it passes nothing).
double push_depth(const EdgeFrame& f, double moved) {
  return f.depth * std::abs(moved) / std::max(std::abs(f.tip_motion), std::abs(f.end_motion));
}

bool edge_crossing(const Vec3& p, const Vec3& q, const EdgeFrame& f, EdgeCrossing* x) {
  const Vec3 pt = p - f.tip;
  const double dp = f.normal.dot(pt), dq = f.normal.dot(q - f.tip);
  if ((dp >= 0) == (dq >= 0)) return false;  // the tie rule of segment_crosses_triangle
  const double at = dp / (dp - dq);
  const Vec3 c = pt + at * (q - p);
  const double along = c.dot(f.axis);
  if (along < 0 || along > f.length) return false;
  const double moved = f.tip_motion + along / f.length * (f.end_motion - f.tip_motion);
  if (moved == 0) return false;
  x->t = at;
  x->behind = f.front - (moved > 0 ? 1.0 : -1.0) * c.dot(f.edge);
  x->moved = moved;
  return true;
}

}  // namespace

bool blade_advances(const CutQuad& quad, const ToolPose& from, const ToolPose& to) {
  return quad.sideways || (to.position - from.position).dot(to.axis) < 0;  // the tip leads
}

bool edge_holds(const Vec3& p, const Vec3& q, const EdgeFrame& f, double* t, double* delta,
                double* direction) {
  EdgeCrossing x;
  if (!edge_crossing(p, q, f, &x) || !(x.behind > 0 && x.behind <= f.depth)) return false;
  *t = x.t;
  *delta = x.behind;
  *direction = x.moved > 0 ? 1.0 : -1.0;
  return true;
}

bool edge_pushes(const Vec3& p, const Vec3& q, const EdgeFrame& f, double* t, double* delta,
                 double* direction) {
  EdgeCrossing x;
  if (!edge_crossing(p, q, f, &x) || !(x.behind > 0 && x.behind <= push_depth(f, x.moved)))
    return false;
  *t = x.t;
  *delta = x.behind;
  *direction = x.moved > 0 ? 1.0 : -1.0;
  return true;
}

bool edge_passes(const Vec3& p, const Vec3& q, const EdgeFrame& f, double* t) {
  EdgeCrossing x;
  if (!edge_crossing(p, q, f, &x) ||
      !(x.behind > f.depth && x.behind <= f.depth + std::abs(x.moved)))
    return false;
  *t = x.t;
  return true;
}

uint32_t side_at_start(uint32_t entry, uint32_t pass) {
  const uint32_t stamp = entry >> 4;
  if (stamp == (pass & kSidePassMask)) return (entry >> 2) & 3u;
  // After: both sides (3, the GPU's lanes merged) keep none.
  if (stamp == ((pass - 1) & kSidePassMask)) return (entry & 3u) == 3u ? kSideNone : entry & 3u;
  return kSideNone;  // not a candidate in the previous substep: the blade has passed
}

uint32_t side_entry(uint32_t pass, uint32_t start, uint32_t after) {
  return (pass & kSidePassMask) << 4 | start << 2 | after;
}

uint32_t side_after(uint32_t start, uint32_t cut) {
  if (start != kSideNone) return start;
  return cut == kSidePlus || cut == kSideMinus ? cut : kSideNone;
}

uint32_t side_from(const Vec3& normal, const Vec3& xi, const Vec3& xj) {
  return normal.dot(xi - xj) >= 0 ? kSidePlus : kSideMinus;
}

bool sides_allow(uint32_t side_i, uint32_t side_j, const Vec3& normal, const Vec3& xi,
                 const Vec3& xj) {
  const uint32_t i_from_j = side_from(normal, xi, xj);
  if (side_i != kSideNone && side_i != i_from_j) return false;
  return side_j == kSideNone || side_j == (i_from_j == kSidePlus ? kSideMinus : kSidePlus);
}

uint32_t side_near_plane(uint32_t side, uint32_t learned, const EdgeFrame& f, const Vec3& x,
                         double band) {
  if (side == kSideNone) return side;
  const double n = f.normal.dot(x - f.tip);
  if ((side == kSidePlus && n < -band) || (side == kSideMinus && n > band)) return kSideNone;
  if (unpack_side_normal(learned).dot(f.normal) < std::cos(kSideTurn)) return kSideNone;
  return side;
}

namespace {

double sign_of(double v) {
  return v >= 0 ? 1.0 : -1.0;
}

uint32_t pack_fraction(double v) {
  const double q = std::floor(std::clamp(v, -1.0, 1.0) * 32767.0 + 0.5);
  return uint32_t(int32_t(q)) & 0xffffu;
}

double unpack_fraction(uint32_t bits) {
  return double(int16_t(uint16_t(bits & 0xffffu))) / 32767.0;
}

}  // namespace

uint32_t pack_side_normal(const Vec3& n) {
  const Vec3 a = n / (std::abs(n.x()) + std::abs(n.y()) + std::abs(n.z()));
  double u = a.x(), v = a.y();
  if (a.z() < 0) {
    u = (1 - std::abs(a.y())) * sign_of(a.x());
    v = (1 - std::abs(a.x())) * sign_of(a.y());
  }
  return pack_fraction(u) | pack_fraction(v) << 16;
}

Vec3 unpack_side_normal(uint32_t word) {
  double u = unpack_fraction(word), v = unpack_fraction(word >> 16);
  const double z = 1 - std::abs(u) - std::abs(v);
  if (z < 0) {
    const double fu = (1 - std::abs(v)) * sign_of(u), fv = (1 - std::abs(u)) * sign_of(v);
    u = fu;
    v = fv;
  }
  return Vec3(u, v, z).normalized();
}

uint32_t side_after_lapse(uint32_t start, uint32_t held, uint32_t cut) {
  return start != kSideNone && held == kSideNone ? kSideNone : side_after(held, cut);
}

double side_band(double body_radius, double spacing) {
  return std::max(body_radius, spacing);
}

double cut_candidate_reach(const std::vector<ContactTool>& tools, double spacing, double support) {
  bool cuts = false;
  double reach = spacing;
  for (const ContactTool& t : tools) {
    cuts = cuts || t.blade.cuts();
    if (t.blade.cuts()) reach = std::max(reach, t.blade.reach);
  }
  return cuts ? reach + support : spacing;
}

bool blades_sever_in_reach_only(const std::vector<ContactTool>& tools) {
  for (const ContactTool& t : tools)
    if (t.blade.cuts() && t.blade.threshold != 0) return false;
  return true;
}

double pair_area_share(double volume_sum, double s_sum) {
  return s_sum > 0 ? volume_sum / s_sum : 0.0;
}

Vec3 bounded_edge_push(const Vec3& force, double threshold) {
  const double size = force.norm();
  return size > threshold ? Vec3(force * (threshold / size)) : force;
}

double edge_force(const Vec3& on_tool, const Vec3& edge) {
  return std::max(0.0, -on_tool.dot(edge));
}

double cut_force(const Vec3& on_tool, const CutQuad& quad) {
  const Vec3 axis = (quad.corner[1] - quad.corner[0]).normalized();
  return std::max({0.0, -on_tool.dot(quad.edge), on_tool.dot(axis)});
}

template <class Real>
bool segment_crosses_triangle(const Eigen::Matrix<Real, 3, 1>& p,
                              const Eigen::Matrix<Real, 3, 1>& q,
                              const Eigen::Matrix<Real, 3, 1>& a,
                              const Eigen::Matrix<Real, 3, 1>& b,
                              const Eigen::Matrix<Real, 3, 1>& c, Real* t) {
  using V3 = Eigen::Matrix<Real, 3, 1>;
  // Everything relative to a: the products stay at the scale of the blade's motion.
  const V3 pa = p - a, qa = q - a, ba = b - a, ca = c - a;
  const V3 n = ba.cross(ca);
  const Real sp = n.dot(pa), sq = n.dot(qa);
  if ((sp >= 0) == (sq >= 0)) return false;  // same side; on the plane counts as positive
  // The segment's orientation against each edge (signed volumes of p q and the edge).
  const V3 d = qa - pa;
  const V3 ap = -pa, bp = ba - pa, cp = ca - pa;
  const Real s1 = d.dot(ap.cross(bp));
  const Real s2 = d.dot(bp.cross(cp));
  const Real s3 = d.dot(cp.cross(ap));
  const bool inside = (s1 >= 0 && s2 >= 0 && s3 >= 0) || (s1 <= 0 && s2 <= 0 && s3 <= 0);
  if (inside && t) *t = sp / (sp - sq);
  return inside;
}

template <class Real>
bool segment_crosses_quad(const Eigen::Matrix<Real, 3, 1>& p, const Eigen::Matrix<Real, 3, 1>& q,
                          const std::array<Eigen::Matrix<Real, 3, 1>, 4>& quad, Real* t) {
  return segment_crosses_triangle<Real>(p, q, quad[0], quad[1], quad[2], t) ||
         segment_crosses_triangle<Real>(p, q, quad[0], quad[2], quad[3], t);
}

template <class Real>
bool blade_severs(const Eigen::Matrix<Real, 3, 1>& p, const Eigen::Matrix<Real, 3, 1>& q,
                  const std::array<Eigen::Matrix<Real, 3, 1>, 4>& quad, Real* t) {
  using V3 = Eigen::Matrix<Real, 3, 1>;
  Real at = 0;
  if (!segment_crosses_quad<Real>(p, q, quad, &at)) return false;
  // The crossing against the front p0 -> p3 (relative to p0, as the crossing test).
  const V3 x = p - quad[0] + at * (q - p), front = quad[3] - quad[0];
  const Real len2 = front.squaredNorm();
  const Real s = len2 > 0 ? std::clamp(x.dot(front) / len2, Real(0), Real(1)) : Real(0);
  if ((x - s * front).norm() < Real(kCutTieTolerance)) return false;
  if (t) *t = at;
  return true;
}

namespace {

double point_segment_distance(const Vec3& x, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double s = len2 > 0 ? std::clamp((x - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (x - (a + s * ab)).norm();
}

double triangle_tie_distance(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b,
                             const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a);
  const double area2 = n.norm();
  if (!(area2 > 0)) return std::numeric_limits<double>::infinity();  // never crosses
  const Vec3 un = n / area2;
  const double dp = un.dot(p - a), dq = un.dot(q - a);
  double tie = std::min(std::abs(dp), std::abs(dq));
  if (dp != dq) {  // where the segment's line meets the plane, against the edges
    const double s = dp / (dp - dq);
    const Vec3 x = p + s * (q - p);
    tie = std::min({tie, point_segment_distance(x, a, b), point_segment_distance(x, b, c),
                    point_segment_distance(x, c, a)});
  }
  return tie;
}

}  // namespace

double crossing_tie_distance(const Vec3& p, const Vec3& q, const std::array<Vec3, 4>& quad) {
  return std::min(triangle_tie_distance(p, q, quad[0], quad[1], quad[2]),
                  triangle_tie_distance(p, q, quad[0], quad[2], quad[3]));
}

template bool segment_crosses_triangle<double>(const Vec3&, const Vec3&, const Vec3&, const Vec3&,
                                               const Vec3&, double*);
template bool segment_crosses_triangle<float>(const Eigen::Vector3f&, const Eigen::Vector3f&,
                                              const Eigen::Vector3f&, const Eigen::Vector3f&,
                                              const Eigen::Vector3f&, float*);
template bool blade_severs<double>(const Vec3&, const Vec3&, const std::array<Vec3, 4>&, double*);
template bool blade_severs<float>(const Eigen::Vector3f&, const Eigen::Vector3f&,
                                  const std::array<Eigen::Vector3f, 4>&, float*);
template bool segment_crosses_quad<double>(const Vec3&, const Vec3&, const std::array<Vec3, 4>&,
                                           double*);
template bool segment_crosses_quad<float>(const Eigen::Vector3f&, const Eigen::Vector3f&,
                                          const std::array<Eigen::Vector3f, 4>&, float*);

}  // namespace phyxel
