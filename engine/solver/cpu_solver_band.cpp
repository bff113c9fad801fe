// CpuSolver: the SCNI band round a blade's cut (docs/cutting.md, "Stiffness of a cut body";
// the smoothed gradients are scni_band.h's, shared with tools/slit_static_solve). A band cell's
// energy is sum_b V_b W(I + G_b) over the 2^3 boxes of its phyxel's cell, G_b = sum_j u_j c_bj^T;
// the force on a node j is -sum over the cells listing it of V_b P_b c_bj, gathered per node
// through a transposed list (no scatter: the sums do not depend on the thread count).
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/solver/cpu_solver.h"
#include "engine/solver/scni_band.h"

namespace phyxel {

template <class Real>
void CpuSolver<Real>::refresh_band(size_t upto) {
  if (upto <= quads_built_) return;
  const size_t first = quads_built_, n = size();
  quads_built_ = upto;
  if (band_of_.empty()) {
    band_of_.assign(n, -1);
    object_lo_.assign(support_.size(), Vec3::Constant(std::numeric_limits<double>::infinity()));
    object_hi_.assign(support_.size(), Vec3::Constant(-std::numeric_limits<double>::infinity()));
    for (size_t i = 0; i < n; ++i) {
      object_lo_[object_[i]] = object_lo_[object_[i]].cwiseMin(rest_d_[i]);
      object_hi_[object_[i]] = object_hi_[object_[i]].cwiseMax(rest_d_[i]);
    }
  }
  // Phyxels within the band width of the new quads join the band; band cells whose Gauss points
  // see across them (within h + s) are to be built again, once no quad newer than `upto` (the
  // cut still passing) reaches them.
  const auto nearest = [&](size_t i, size_t from, size_t to, double enough) {
    double d = std::numeric_limits<double>::infinity();
    for (size_t q = from; q < to && d >= enough; ++q)
      d = std::min(d, distance_to_quad(rest_d_[i], cut_quads_[q]));
    return d;
  };
  std::vector<uint32_t> build, joined;
  for (size_t i = 0; i < n; ++i) {
    const uint32_t o = object_[i];
    if (!(band_width_[o] > 0) || (flags_[i] & kRemoved)) continue;
    const double rebuild = std::max(band_width_[o], support_[o] + spacing_[o]);
    const double d = nearest(i, first, upto, band_width_[o]);
    if (d < band_width_[o] && band_of_[i] < 0) {
      band_of_[i] = int32_t(band_.size());
      band_.push_back(BandCell{uint32_t(i), {}, true});
    }
    if (band_of_[i] < 0) continue;
    BandCell& cell = band_[size_t(band_of_[i])];
    cell.dirty = cell.dirty || d < rebuild;
    if (cell.dirty && !(nearest(i, upto, cut_quads_.size(), rebuild) < rebuild)) {
      build.push_back(uint32_t(i));
      if (cell.box.empty()) joined.push_back(uint32_t(i));
    }
  }
  if (build.empty()) return;
  const long nb = long(build.size());
  const PointGrid grid(rest_d_, max_support_);
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads_for(nb * 256))
  for (long k = 0; k < nb; ++k) build_band_cell(size_t(band_of_[build[k]]), grid);
  precompute_touched(joined);  // their hourglass term is off from now
  build_band_gather();
  compute_forces();
}

template <class Real>
void CpuSolver<Real>::build_band_cell(size_t c, const PointGrid& grid) {
  const uint32_t i = band_[c].phyxel, o = object_[i];
  const double s = spacing_[o], h = support_[o];
  ScniCell cell = lattice_cell(rest_d_[i], s, object_lo_[o], object_hi_[o]);
  // A fixed phyxel's cell holds the body on the wall where its face on the object's bounds
  // faces a free phyxel: that face takes u = 0 (the clamp), not the fit.
  if (flags_[i] & kFixed)
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side) {
        const double bound = side ? object_hi_[o][axis] : object_lo_[o][axis];
        const double face = side ? cell.hi[axis] : cell.lo[axis];
        if (std::abs(face - bound) > 1e-9 * s) continue;
        Vec3 inward = rest_d_[i];
        inward[axis] += side ? -s : s;
        for (const uint32_t j : grid.within(inward))
          if ((rest_d_[j] - inward).norm() < 1e-3 * s && !(flags_[j] & kFixed))
            cell.clamped[2 * axis + side] = true;
      }
  std::vector<const std::array<Vec3, 4>*> near;  // quads a line of sight from the cell may cross
  for (const auto& q : cut_quads_)
    if (distance_to_quad(rest_d_[i], q) < h + s) near.push_back(&q);
  const PairWeight visible = [&](const Vec3& from, uint32_t j, double w0) {
    if (object_[j] != o || (flags_[j] & kRemoved)) return 0.0;
    for (const auto* q : near)
      if (blade_severs<double>(from, rest_d_[j], *q)) return 0.0;
    return w0;
  };
  const std::vector<ScniBox> boxes = scni_boxes(rest_d_, grid, h, cell, visible);
  double total = 0;
  for (const ScniBox& b : boxes) total += b.volume;
  band_[c].dirty = false;
  std::vector<BandBox>& out = band_[c].box;
  out.assign(boxes.size(), BandBox{});
  for (size_t b = 0; b < boxes.size(); ++b) {
    // The boxes' energy weights add up to the phyxel's quadrature volume (the cell's part
    // inside the shape); their gradients are the geometric boxes'.
    out[b].volume = Real(boxes[b].volume * double(volume_[i]) / total);
    out[b].node = boxes[b].node;
    for (const Vec3& k : boxes[b].coeff) out[b].coeff.push_back(k.cast<Real>());
  }
}

template <class Real>
void CpuSolver<Real>::build_band_gather() {
  const size_t n = size();
  gather_offset_.assign(n + 1, 0);
  for (const BandCell& cell : band_)
    for (const BandBox& box : cell.box)
      for (const uint32_t j : box.node) ++gather_offset_[j + 1];
  for (size_t k = 0; k < n; ++k) gather_offset_[k + 1] += gather_offset_[k];
  gather_.assign(gather_offset_[n], GatherEntry{});
  std::vector<uint32_t> fill(gather_offset_.begin(), gather_offset_.end() - 1);
  for (uint32_t c = 0; c < band_.size(); ++c)
    for (uint32_t b = 0; b < band_[c].box.size(); ++b)
      for (uint32_t k = 0; k < band_[c].box[b].node.size(); ++k)
        gather_[fill[band_[c].box[b].node[k]]++] = GatherEntry{c, b, k};
}

template <class Real>
typename CpuSolver<Real>::M3 CpuSolver<Real>::box_gradient(long c, size_t b) const {
  const BandBox& box = band_[c].box[b];
  M3 g = M3::Zero();
  for (size_t k = 0; k < box.node.size(); ++k) g += u_[box.node[k]] * box.coeff[k].transpose();
  return g;
}

template <class Real>
void CpuSolver<Real>::band_stress(long c) {
  const uint32_t i = band_[c].phyxel;
  const bool active = awake_[object_[i]] && !(flags_[i] & kRemoved);
  for (size_t b = 0; b < band_[c].box.size(); ++b) {
    BandBox& box = band_[c].box[b];
    if (!active) {
      box.stress = M3::Zero();
      continue;
    }
    const M3 f = M3::Identity() + box_gradient(c, b);
    box.stress = box.volume * first_piola<Real>(f, params_[i], nullptr);
  }
}

template <class Real>
typename CpuSolver<Real>::V3 CpuSolver<Real>::band_force(uint32_t k) const {
  V3 f = V3::Zero();
  for (uint32_t e = gather_offset_[k]; e < gather_offset_[k + 1]; ++e) {
    const GatherEntry& g = gather_[e];
    const BandBox& box = band_[g.cell].box[g.box];
    f -= box.stress * box.coeff[g.slot];
  }
  return f;
}

template <class Real>
double CpuSolver<Real>::band_energy(long c) const {
  const uint32_t i = band_[c].phyxel;
  if (flags_[i] & kRemoved) return 0;
  double total = 0;
  for (size_t b = 0; b < band_[c].box.size(); ++b) {
    Real w = 0;
    first_piola<Real>(M3::Identity() + box_gradient(c, b), params_[i], &w);
    total += double(band_[c].box[b].volume * w);
  }
  return total;
}

// The members defined here (the class itself is instantiated in cpu_solver.cpp).
#define PHYXEL_BAND_MEMBERS(Real)                                                 \
  template void CpuSolver<Real>::refresh_band(size_t);                            \
  template void CpuSolver<Real>::build_band_cell(size_t, const PointGrid&);       \
  template void CpuSolver<Real>::build_band_gather();                             \
  template CpuSolver<Real>::M3 CpuSolver<Real>::box_gradient(long, size_t) const; \
  template void CpuSolver<Real>::band_stress(long);                               \
  template CpuSolver<Real>::V3 CpuSolver<Real>::band_force(uint32_t) const;       \
  template double CpuSolver<Real>::band_energy(long) const;
PHYXEL_BAND_MEMBERS(double)
PHYXEL_BAND_MEMBERS(float)
#undef PHYXEL_BAND_MEMBERS

}  // namespace phyxel
