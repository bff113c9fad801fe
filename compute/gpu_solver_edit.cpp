// GpuSolver: topology edits in place. Pairs and phyxels are never taken out of the buffers:
// a removed pair keeps its CSR slot with weight 0 (on both sides), a removed phyxel keeps its
// slot with kRemoved set, and the precompute pass is rerun for the phyxels whose neighbourhood
// changed (the indexed mode of solver_precompute). The step passes read the stored weights of
// the phyxels flagged kFlagPairsEdited and recompute everyone else's from x0.
#include <set>
#include <stdexcept>
#include <string>

#include "compute/gpu_solver.h"
#include "compute/gpu_solver_kernels.h"

namespace phyxel::gpu {

using namespace layout;

void GpuSolver::remove_phyxels(const std::vector<uint32_t>& ids) {
  if (ids.empty()) return;
  std::vector<uint32_t> flags = download<uint32_t>(*ctx_, flags_, count_);
  std::vector<float> weights = download<float>(*ctx_, weight_, pairs_);
  const NeighbourLists& nbr = neighbours_;
  std::set<uint32_t> touched;
  for (uint32_t i : ids) {
    if (i >= count_) throw std::out_of_range("remove_phyxels: no phyxel " + std::to_string(i));
    flags[i] |= kFlagRemoved | kFlagPairsEdited;
    phyxel_flags_[i] |= kRemoved;
    touched.insert(i);
    for (uint32_t k = nbr.offset[i]; k < nbr.offset[i + 1]; ++k) {
      const uint32_t j = nbr.index[k];
      weights[k] = 0.0f;
      const size_t back = nbr.slot(j, i);
      if (back != NeighbourLists::kNoSlot) weights[back] = 0.0f;
      if (!alive_.empty()) {  // pair_alive() answers from the log's mask once there is one
        alive_[k] = 0;
        if (back != NeighbourLists::kNoSlot) alive_[back] = 0;
      }
      flags[j] |= kFlagPairsEdited;
      touched.insert(j);
    }
  }
  apply_edit(flags, weights, std::vector<uint32_t>(touched.begin(), touched.end()));
  build_pass_lists();  // removed phyxels leave every pass
  compute_forces();
}

void GpuSolver::apply_edit(const std::vector<uint32_t>& flags, const std::vector<float>& weights,
                           const std::vector<uint32_t>& touched) {
  upload(*ctx_, flags_, flags);
  upload(*ctx_, weight_, weights);
  if (list_.size() < touched.size() * sizeof(uint32_t))
    list_ =
        Buffer(*ctx_, touched.size() * sizeof(uint32_t), MemoryIntent::Device, "precompute list");
  upload(*ctx_, list_, touched);
  Recorder& rec = *rec_[0];
  dispatch(
      rec, kernels_->precompute, PrecomputePush{uint32_t(touched.size()), 1},
      {nbr_offset_, nbr_index_, weight_, local_, flags_, classes_, rest_, ainv_, resid_, list_},
      uint32_t(touched.size()));
  rec.submit_and_wait();
  count_flags();
}

}  // namespace phyxel::gpu
