// CpuSolver: cutting (engine/solver/cutting.h; the GPU twin is compute/shaders/tool_sever.comp).
// After the contacts of a step, each blade whose edge force reached its threshold tests the
// rows of the broad phase's candidates against the quad it swept in the step (and a blade with
// a threshold, whatever its force, against the pairs its edge carries past its reach); a pair
// gets weight 0 on both sides, and the precompute reruns for the phyxels whose rows changed.
#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>

#include "engine/solver/cpu_solver.h"

namespace phyxel {
namespace {

// The blade body's strip (docs/cutting.md, "The blade's body"): the part of the blade's plane
// at the substep's end pose within the body's radius of the blade. A pair whose segment crosses
// it passes through the body, which separates it whatever the blade's reach ahead (the GPU twin
// builds the same strip in tool_sever.comp).
std::array<Vec3, 4> body_strip(const Blade& blade, const ToolPose& to, const Vec3& edge,
                               double radius) {
  const Vec3 tip = to.position, end = to.position + blade.length * to.axis;
  return {tip - radius * edge, end - radius * edge, end + radius * edge, tip + radius * edge};
}

// The radius of a scalpel's body (its capsule; 0 for another shape).
double blade_body_radius(const ContactTool& tool) {
  return tool.shape.type == ToolShape::Type::Capsule ? tool.shape.radius : 0.0;
}

}  // namespace

template <class Real>
bool CpuSolver<Real>::sever(uint32_t i, uint32_t k, float t) {
  if (w_[k] == Real(0)) return false;
  const uint32_t j = nbr_.index[k];
  w_[k] = Real(0);
  if (const size_t back = nbr_.slot(j, i); back != NeighbourLists::kNoSlot) w_[back] = Real(0);
  severed_.push_back(i < j ? SeveredPair{i, j, t} : SeveredPair{j, i, 1.0f - t});
  return true;
}

template <class Real>
void CpuSolver<Real>::apply_cuts() {
  ++cut_pass_;  // every substep: a side not renewed in the last one has lapsed
  const size_t nt = tools_.size();
  if (now_.size() != nt || samples_.size() < nt) return;  // no motion yet: nothing cuts
  const size_t first = severed_.size();
  std::vector<uint32_t> touched;
  for (size_t tool = 0; tool < nt; ++tool)
    if (tools_[tool].blade.cuts()) cut_with_blade(tool, touched);
  if (severed_.size() != first) precompute_touched(touched);
}

template <class Real>
void CpuSolver<Real>::cut_with_blade(size_t tool, std::vector<uint32_t>& touched) {
  const Blade& blade = tools_[tool].blade;
  const ToolMotion& m = now_[tool];
  const double reach = blade_reach(blade, contact_spacing_);
  const CutQuad quad = swept_quad(blade, m.from, m.to, reach);
  const size_t nt = tools_.size();
  // A blade in the cutting state goes on cutting while it advances (docs/cutting.md, "Rupture and
  // the cutting state").
  const bool advances = blade_advances(quad, m.from, m.to);
  const bool cuts =
      cut_force(samples_[samples_.size() - nt + tool].force, quad) >= blade.threshold ||
      (blade_cutting_[tool] && advances);
  bool in_tissue = false;  // the blade crosses a pair (severed or not) in this substep
  const double body = blade_body_radius(tools_[tool]);
  const double band = side_band(body, contact_spacing_);  // where a kept side still holds
  const EdgeFrame edge = edge_frame(blade, quad, m.to, body, reach);
  // Below the threshold a blade whose edge holds pairs still severs those it carries past
  // its reach (edge_passes); threshold 0 always cuts and holds nothing.
  const bool resists = edge.stiffness > 0;
  // One side per phyxel for blades with a threshold only (docs/cutting.md: at 0 it kept
  // breast_resection's cone joined at its apex, where the blade's plane turns about phyxels).
  const bool sided = blade.threshold > 0;
  blade_cutting_[tool] = 0;
  if (!cuts && !resists && !sided) return;
  const std::array<Vec3, 4>& c = quad.corner;
  const std::array<Vec3, 4> strip = body_strip(blade, m.to, quad.edge, body);
  uint32_t* sides = blade_side_.data() + tool * size();
  uint32_t* learned = blade_side_.data() + (nt + tool) * size();
  auto crosses_blade = [&](const Vec3& p, const Vec3& q, double* t) {
    double behind = 0, direction = 0;
    if (cuts &&
        (blade_severs<double>(p, q, c, t) || (body > 0 && blade_severs<double>(p, q, strip, t)) ||
         (resists && edge_holds(p, q, edge, t, &behind, &direction))))
      return true;
    return resists && edge_passes(p, q, edge, t);
  };
  static const std::vector<uint32_t> kNone;
  // No candidate within the blades' reach in this chunk (find_candidates): no pair to test.
  for (const uint32_t i : blades_near_ ? candidates_ : kNone) {
    const Vec3 xi = rest_d_[i] + u_[i].template cast<double>();
    const uint32_t start = sided ? side_at_start(sides[i], cut_pass_) : kSideNone;
    const uint32_t side_i = sided ? side_held(tool, i, xi, edge, cut_pass_, band) : kSideNone;
    uint32_t cut_to = kSideNone;  // the sides of i's pairs this blade crosses (severed or not)
    for (uint32_t k = nbr_.offset[i]; (cuts || resists) && k < nbr_.offset[i + 1]; ++k) {
      if (!sided && w_[k] == Real(0)) continue;  // no side to learn from a severed pair
      const uint32_t j = nbr_.index[k];
      const Vec3 xj = rest_d_[j] + u_[j].template cast<double>();
      // The canonical order (lower index first): both sides of a pair decide alike.
      double t = 0;
      const bool crosses = i < j ? crosses_blade(xi, xj, &t) : crosses_blade(xj, xi, &t);
      in_tissue = in_tissue || crosses;
      if (!crosses || (sided && !sides_allow(side_i, side_held(tool, j, xj, edge, cut_pass_, band),
                                             edge.normal, xi, xj)))
        continue;
      cut_to |= side_from(edge.normal, xi, xj);
      if (w_[k] == Real(0)) continue;
      sever(i, k, float(i < j ? t : 1 - t));
      touched.push_back(i);
      touched.push_back(j);
    }
    if (!sided) continue;
    const uint32_t after = side_after_lapse(start, side_i, cut_to);
    sides[i] = side_entry(cut_pass_, start, after);  // readers apply the lapse to start
    // Learned in this pass (no reader needs it before the next): the plane it was learned on.
    if (start == kSideNone && after != kSideNone) learned[i] = pack_side_normal(edge.normal);
  }
  blade_cutting_[tool] = blade.threshold > 0 && cuts && advances && in_tissue;
  // The band looks across the surface the blade cut (the quad; its body's strip lies in it),
  // not at pairs only carried past the reach.
  if (cuts && band_.on() && !candidates_.empty()) band_.add_cut(c, reach);
}

template <class Real>
EdgeFrame CpuSolver<Real>::substep_edge(size_t tool) const {
  const Blade& blade = tools_[tool].blade;
  if (!blade.cuts() || !(blade.threshold > 0) || now_.size() != tools_.size()) return {};
  const ToolMotion& m = now_[tool];
  const double reach = blade_reach(blade, contact_spacing_);
  const CutQuad quad = swept_quad(blade, m.from, m.to, reach);
  return edge_frame(blade, quad, m.to, blade_body_radius(tools_[tool]), reach);
}

template <class Real>
std::vector<Vec3> CpuSolver<Real>::blade_side_normals() const {
  std::vector<Vec3> normals(tools_.size(), Vec3::Zero());
  if (blade_side_.empty()) return normals;
  for (size_t tool = 0; tool < tools_.size(); ++tool)
    if (tools_[tool].blade.cuts() && tools_[tool].blade.threshold > 0)
      normals[tool] = substep_edge(tool).normal;
  return normals;
}

template <class Real>
Vec3 CpuSolver<Real>::kept_side(size_t tool, uint32_t i, const Vec3& normal) const {
  if (normal.isZero(0)) return Vec3::Zero();
  // apply_cuts counts this substep after the contacts.
  const uint32_t side = side_at_start(blade_side_[tool * size() + i], cut_pass_ + 1);
  return side == kSidePlus ? normal : side == kSideMinus ? Vec3(-normal) : Vec3::Zero();
}

template <class Real>
double CpuSolver<Real>::plane_crossings(uint32_t i, const Vec3& normal) const {
  const Vec3 xi = rest_d_[i] + u_[i].template cast<double>();
  double sum = 0;
  for (uint32_t k = nbr_.offset[i]; k < nbr_.offset[i + 1]; ++k) {
    const uint32_t j = nbr_.index[k];
    sum += std::abs(normal.dot(rest_d_[j] + u_[j].template cast<double>() - xi));
  }
  return 0.5 * sum;
}

template <class Real>
uint32_t CpuSolver<Real>::side_held(size_t tool, uint32_t i, const Vec3& x, const EdgeFrame& edge,
                                    uint32_t pass, double band) const {
  const size_t n = size();
  return side_near_plane(side_at_start(blade_side_[tool * n + i], pass),
                         blade_side_[(tools_.size() + tool) * n + i], edge, x, band);
}

template <class Real>
Vec3 CpuSolver<Real>::held_pairs_force(uint32_t i, const EdgeFrame& edge, size_t tool,
                                       double band) const {
  const Vec3 xi = rest_d_[i] + u_[i].template cast<double>();
  const uint32_t pass = cut_pass_ + 1;  // apply_cuts counts this substep after the contacts
  const uint32_t side_i = side_held(tool, i, xi, edge, pass, band);
  Vec3 total = Vec3::Zero();
  double s_i = -1;
  for (uint32_t k = nbr_.offset[i]; k < nbr_.offset[i + 1]; ++k) {
    if (w_[k] == Real(0)) continue;
    const uint32_t j = nbr_.index[k];
    const Vec3 xj = rest_d_[j] + u_[j].template cast<double>();
    double t = 0, behind = 0, direction = 0;  // in the canonical order, as apply_cuts
    if (!(i < j ? edge_pushes(xi, xj, edge, &t, &behind, &direction)
                : edge_pushes(xj, xi, edge, &t, &behind, &direction)) ||
        !sides_allow(side_i, side_held(tool, j, xj, edge, pass, band), edge.normal, xi, xj))
      continue;
    if (s_i < 0) s_i = plane_crossings(i, edge.normal);
    const double s_j = plane_crossings(j, edge.normal);
    const double area = i < j ? pair_area_share(double(volume_[i]) + double(volume_[j]), s_i + s_j)
                              : pair_area_share(double(volume_[j]) + double(volume_[i]), s_j + s_i);
    total += (edge.stiffness * area * behind * (i < j ? 1 - t : t) * direction) * edge.edge;
  }
  return total;
}

template <class Real>
void CpuSolver<Real>::apply_edge_resistance(Real dt, std::vector<ToolContactSample>& felt) {
  for (size_t tool = 0; tool < tools_.size(); ++tool) {
    const EdgeFrame edge = substep_edge(tool);
    if (!(edge.stiffness > 0)) continue;
    const double band = side_band(blade_body_radius(tools_[tool]), contact_spacing_);
    for (const uint32_t i : candidates_) {
      if (flags_[i] & (kFixed | kRemoved)) continue;
      const Vec3 force =
          bounded_edge_push(held_pairs_force(i, edge, tool, band), tools_[tool].blade.threshold);
      if (force.isZero(0)) continue;
      v_[i] += dt / mass_[i] * force.template cast<Real>();
      felt[tool].force -= force;
    }
  }
}

template <class Real>
void CpuSolver<Real>::precompute_touched(std::vector<uint32_t>& touched) {
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  for (const uint32_t i : touched) {
    regularised_count_ -= regularised_[i];
    precompute(i);
    regularised_count_ += regularised_[i];
  }
}

template <class Real>
void CpuSolver<Real>::sort_severed_from(size_t first) {
  std::sort(severed_.begin() + std::min(first, severed_.size()), severed_.end(),
            [](const SeveredPair& a, const SeveredPair& b) {
              return a.i != b.i ? a.i < b.i : a.j < b.j;
            });
}

template <class Real>
void CpuSolver<Real>::sever_pairs(const std::vector<SeveredPair>& pairs) {
  std::vector<uint32_t> touched;
  for (const SeveredPair& p : pairs) {
    if (p.i >= size() || p.j >= size())
      throw std::invalid_argument("sever_pairs: no phyxel " + std::to_string(std::max(p.i, p.j)));
    const size_t at = nbr_.slot(p.i, p.j);
    if (at == NeighbourLists::kNoSlot)
      throw std::invalid_argument("sever_pairs: phyxels " + std::to_string(p.i) + " and " +
                                  std::to_string(p.j) + " are not neighbours");
    if (sever(p.i, uint32_t(at), p.t)) {
      severed_.back().torn = p.torn;
      touched.push_back(p.i);
      touched.push_back(p.j);
    }
  }
  precompute_touched(touched);
  compute_forces();
}

template <class Real>
std::vector<BladeSide> CpuSolver<Real>::blade_sides(size_t tool) const {
  std::vector<BladeSide> kept;
  if (!tools_.at(tool).blade.cuts()) return kept;
  const uint32_t* sides = blade_side_.data() + tool * size();
  const uint32_t* learned = blade_side_.data() + (tools_.size() + tool) * size();
  for (uint32_t i = 0; i < size(); ++i)
    if (const uint32_t side = side_at_start(sides[i], cut_pass_ + 1); side != kSideNone)
      kept.push_back({i, side, learned[i]});
  return kept;
}

template <class Real>
void CpuSolver<Real>::restore_blade_sides(size_t tool, const std::vector<BladeSide>& kept) {
  if (tool >= tools_.size() || (!kept.empty() && !tools_[tool].blade.cuts()))
    throw std::invalid_argument("restore_blade_sides: tool " + std::to_string(tool) +
                                " has no blade");
  uint32_t* sides = blade_side_.data() + tool * size();
  uint32_t* learned = blade_side_.data() + (tools_.size() + tool) * size();
  for (const BladeSide& b : kept) {
    if (b.phyxel >= size() || (b.side != kSidePlus && b.side != kSideMinus))
      throw std::invalid_argument("restore_blade_sides: bad side for phyxel " +
                                  std::to_string(b.phyxel));
    sides[b.phyxel] = side_entry(cut_pass_, kSideNone, b.side);
    learned[b.phyxel] = b.normal;
  }
}

template <class Real>
bool CpuSolver<Real>::blade_cutting(size_t tool) const {
  return tool < blade_cutting_.size() && blade_cutting_[tool] != 0;
}

template <class Real>
void CpuSolver<Real>::restore_blade_cutting(size_t tool, bool on) {
  if (tool >= tools_.size() ||
      (on && !(tools_[tool].blade.cuts() && tools_[tool].blade.threshold > 0)))
    throw std::invalid_argument("restore_blade_cutting: tool " + std::to_string(tool) +
                                " has no blade with a threshold");
  blade_cutting_[tool] = on ? 1 : 0;
}

template <class Real>
void CpuSolver<Real>::remove_phyxels(const std::vector<uint32_t>& ids) {
  std::vector<uint32_t> touched;
  for (const uint32_t i : ids) {
    if (i >= size()) throw std::out_of_range("remove_phyxels: no phyxel " + std::to_string(i));
    flags_[i] |= kRemoved;
    for (uint32_t k = nbr_.offset[i]; k < nbr_.offset[i + 1]; ++k) {
      const uint32_t j = nbr_.index[k];
      w_[k] = Real(0);
      if (const size_t back = nbr_.slot(j, i); back != NeighbourLists::kNoSlot) w_[back] = Real(0);
      touched.push_back(j);
    }
    touched.push_back(i);
  }
  if (touched.empty()) return;
  for (Grip& g : grips_)  // the jaws hold nothing that left the physics
    std::erase_if(g.held, [&](const GripEntry& e) { return (flags_[e.phyxel] & kRemoved) != 0; });
  precompute_touched(touched);
  build_pass_lists();
  compute_forces();
}

// The members defined here (the class itself is instantiated in cpu_solver.cpp).
#define PHYXEL_CUTTING_MEMBERS(Real)                                                            \
  template bool CpuSolver<Real>::sever(uint32_t, uint32_t, float);                              \
  template void CpuSolver<Real>::apply_cuts();                                                  \
  template void CpuSolver<Real>::cut_with_blade(size_t, std::vector<uint32_t>&);                \
  template std::vector<BladeSide> CpuSolver<Real>::blade_sides(size_t) const;                   \
  template void CpuSolver<Real>::restore_blade_sides(size_t, const std::vector<BladeSide>&);    \
  template bool CpuSolver<Real>::blade_cutting(size_t) const;                                   \
  template void CpuSolver<Real>::restore_blade_cutting(size_t, bool);                           \
  template EdgeFrame CpuSolver<Real>::substep_edge(size_t) const;                               \
  template std::vector<Vec3> CpuSolver<Real>::blade_side_normals() const;                       \
  template Vec3 CpuSolver<Real>::kept_side(size_t, uint32_t, const Vec3&) const;                \
  template double CpuSolver<Real>::plane_crossings(uint32_t, const Vec3&) const;                \
  template Vec3 CpuSolver<Real>::held_pairs_force(uint32_t, const EdgeFrame&, size_t, double)   \
      const;                                                                                    \
  template uint32_t CpuSolver<Real>::side_held(size_t, uint32_t, const Vec3&, const EdgeFrame&, \
                                               uint32_t, double) const;                         \
  template void CpuSolver<Real>::apply_edge_resistance(Real, std::vector<ToolContactSample>&);  \
  template void CpuSolver<Real>::precompute_touched(std::vector<uint32_t>&);                    \
  template void CpuSolver<Real>::sort_severed_from(size_t);                                     \
  template void CpuSolver<Real>::sever_pairs(const std::vector<SeveredPair>&);                  \
  template void CpuSolver<Real>::remove_phyxels(const std::vector<uint32_t>&);
PHYXEL_CUTTING_MEMBERS(double)
PHYXEL_CUTTING_MEMBERS(float)
#undef PHYXEL_CUTTING_MEMBERS

}  // namespace phyxel
