// CpuSolver: the SCNI band round a blade's cut (docs/cutting.md, "Stiffness of a cut body"; the
// cells and their smoothed gradients are CutBand's, shared with the GPU solver). A band cell's
// energy is sum_b V_b W(I + G_b) over the 2^3 boxes of its phyxel's cell, G_b = sum_j u_j c_bj^T;
// the force on a node j is -sum over the cells listing it of V_b P_b c_bj, gathered per node
// through a transposed list (no scatter: the sums do not depend on the thread count).
#include "engine/solver/cpu_solver.h"

namespace phyxel {

template <class Real>
void CpuSolver<Real>::use_band(const CutBand::Refresh& refresh) {
  if (refresh.built.empty()) return;
  band_box_.resize(band_.cells().size());
  for (const uint32_t c : refresh.built) {
    const std::vector<CutBand::Box>& boxes = band_.cells()[c].box;
    std::vector<BandBox>& out = band_box_[c];
    out.assign(boxes.size(), BandBox{});
    for (size_t b = 0; b < boxes.size(); ++b) {
      out[b].volume = Real(boxes[b].volume);
      for (const Vec3& k : boxes[b].coeff) out[b].coeff.push_back(k.cast<Real>());
    }
  }
  std::vector<uint32_t> joined = refresh.joined;
  precompute_touched(joined);  // their hourglass term is off from now
  compute_forces();
}

template <class Real>
typename CpuSolver<Real>::M3 CpuSolver<Real>::box_gradient(long c, size_t b) const {
  const std::vector<uint32_t>& node = band_.cells()[c].box[b].node;
  const BandBox& box = band_box_[c][b];
  M3 g = M3::Zero();
  for (size_t k = 0; k < node.size(); ++k) g += u_[node[k]] * box.coeff[k].transpose();
  return g;
}

template <class Real>
void CpuSolver<Real>::band_stress(long c) {
  const uint32_t i = band_.cells()[c].phyxel;
  const bool active = awake_[object_[i]] && !(flags_[i] & kRemoved);
  for (size_t b = 0; b < band_box_[c].size(); ++b) {
    BandBox& box = band_box_[c][b];
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
  const std::vector<CutBand::GatherEntry>& gather = band_.gather();
  for (uint32_t e = band_.gather_offset()[k]; e < band_.gather_offset()[k + 1]; ++e) {
    const CutBand::GatherEntry& g = gather[e];
    const BandBox& box = band_box_[g.cell][g.box];
    f -= box.stress * box.coeff[g.slot];
  }
  return f;
}

template <class Real>
double CpuSolver<Real>::band_energy(long c) const {
  const uint32_t i = band_.cells()[c].phyxel;
  if (flags_[i] & kRemoved) return 0;
  double total = 0;
  for (size_t b = 0; b < band_box_[c].size(); ++b) {
    Real w = 0;
    first_piola<Real>(M3::Identity() + box_gradient(c, b), params_[i], &w);
    total += double(band_box_[c][b].volume * w);
  }
  return total;
}

// The members defined here (the class itself is instantiated in cpu_solver.cpp).
#define PHYXEL_BAND_MEMBERS(Real)                                                 \
  template void CpuSolver<Real>::use_band(const CutBand::Refresh&);               \
  template CpuSolver<Real>::M3 CpuSolver<Real>::box_gradient(long, size_t) const; \
  template void CpuSolver<Real>::band_stress(long);                               \
  template CpuSolver<Real>::V3 CpuSolver<Real>::band_force(uint32_t) const;       \
  template double CpuSolver<Real>::band_energy(long) const;
PHYXEL_BAND_MEMBERS(double)
PHYXEL_BAND_MEMBERS(float)
#undef PHYXEL_BAND_MEMBERS

}  // namespace phyxel
