// GpuSolver: topology edits in place. Pairs and phyxels are never taken out of the buffers:
// a removed pair keeps its CSR slot with weight 0 (on both sides), a removed phyxel keeps its
// slot with kRemoved set, and the precompute pass is rerun for the phyxels whose neighbourhood
// changed (the indexed mode of solver_precompute). The step passes read the stored weights of
// the phyxels flagged kFlagPairsEdited and recompute everyone else's from x0.
#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

#include "compute/gpu_solver.h"
#include "compute/gpu_solver_kernels.h"

namespace phyxel::gpu {

using namespace layout;

// The flags and weights as the GPU has them, in one submission through a persistent read-back
// buffer. (Aspiration removes phyxels dozens of times a run: a staging buffer and a
// submission per download and upload cost about 15 ms per removal on the H100.)
void GpuSolver::read_flags_and_weights(std::vector<uint32_t>& flags, std::vector<float>& weights) {
  const VkDeviceSize flag_bytes = VkDeviceSize{count_} * 4, weight_bytes = VkDeviceSize{pairs_} * 4;
  if (edit_readback_.size() < flag_bytes + weight_bytes)
    edit_readback_ =
        Buffer(*ctx_, flag_bytes + weight_bytes, MemoryIntent::Readback, "edit read-back");
  Recorder& rec = *rec_[0];
  rec.barrier();
  rec.copy(flags_, edit_readback_, flag_bytes, 0, 0);
  weight_.record_copy_to(rec, edit_readback_, flag_bytes);
  rec.submit_and_wait();
  edit_readback_.invalidate();
  const auto* base = static_cast<const char*>(edit_readback_.mapped());
  flags.resize(count_);
  weights.resize(pairs_);
  std::memcpy(flags.data(), base, flag_bytes);
  std::memcpy(weights.data(), base + flag_bytes, weight_bytes);
}

// Everything of a removal is local to the removed phyxels and their pairs: the host lists the
// flag bits to set (per touched phyxel) and the pair slots to zero from the CSR it keeps, and
// one submission applies them (solver_edit), reruns the precompute over the touched phyxels,
// counts the flags (solver_edit, mode 1) and recomputes the forces (apply_removal), after the
// pass lists' upload. Nothing per phyxel or per pair crosses the bus.
void GpuSolver::remove_phyxels(const std::vector<uint32_t>& ids) {
  settle();
  if (ids.empty()) return;
  const NeighbourLists& nbr = neighbours_;
  // (touched phyxel, flag bits to set), sorted and merged below: no node per entry.
  std::vector<std::pair<uint32_t, uint32_t>> bits;
  std::vector<uint32_t> slots;
  for (uint32_t i : ids) {
    if (i >= count_) throw std::out_of_range("remove_phyxels: no phyxel " + std::to_string(i));
    bits.emplace_back(i, kFlagRemoved | kFlagPairsEdited);
    phyxel_flags_[i] |= kRemoved;
    for (uint32_t k = nbr.offset[i]; k < nbr.offset[i + 1]; ++k) {
      const uint32_t j = nbr.index[k];
      slots.push_back(k);
      const size_t back = nbr.slot(j, i);
      if (back != NeighbourLists::kNoSlot) slots.push_back(static_cast<uint32_t>(back));
      if (!alive_.empty()) {  // pair_alive() answers from the log's mask once there is one
        alive_[k] = 0;
        if (back != NeighbourLists::kNoSlot) alive_[back] = 0;
      }
      bits.emplace_back(j, kFlagPairsEdited);
    }
  }
  std::sort(bits.begin(), bits.end());
  std::vector<uint32_t> edits, touched;  // edits: (phyxel, bits) pairs, ascending
  for (const auto& [phyxel, set] : bits) {
    if (!touched.empty() && touched.back() == phyxel) {
      edits.back() |= set;
      continue;
    }
    edits.insert(edits.end(), {phyxel, set});
    touched.push_back(phyxel);
  }
  remove_from_pass_lists(ids);  // removed phyxels leave every pass; recorded into rec_[0]
  apply_removal(edits, slots, touched);
}

// Records the edits, the precompute and the flag counts into rec_[0] after what is recorded
// there (the pass lists' upload), then the forces (compute_forces submits them all at once: one
// wait per removal, not two), and takes the counts.
void GpuSolver::apply_removal(const std::vector<uint32_t>& edits,
                              const std::vector<uint32_t>& slots,
                              const std::vector<uint32_t>& touched) {
  auto stage = [&](Buffer& b, const void* data, uint64_t bytes, const char* name) {
    if (b.size() < std::max<uint64_t>(bytes, 4))
      b = Buffer(*ctx_, std::max<uint64_t>({bytes, 2 * b.size(), 64}), MemoryIntent::Upload, name);
    std::memcpy(b.mapped(), data, bytes);
  };
  stage(removal_edits_, edits.data(), edits.size() * 4, "removal: flag edits");
  stage(removal_slots_, slots.data(), slots.size() * 4, "removal: pair slots");
  stage(removal_list_, touched.data(), touched.size() * 4, "removal: precompute list");
  if (!removal_counts_)
    removal_counts_ = Buffer(*ctx_, 2 * 4, MemoryIntent::Readback, "removal: flag counts");
  Recorder& rec = *rec_[0];
  const std::initializer_list<BufferRef> bindings = {
      {"Flags", flags_},           {"Edits", removal_edits_},    {"Slots", removal_slots_},
      {"Counts", removal_counts_}, {"IndexLo", nbr_index_.lo()}, {"IndexHi", nbr_index_.hi()},
      {"WeightLo", weight_.lo()},  {"WeightHi", weight_.hi()}};
  const auto n = static_cast<uint32_t>(touched.size()), s = static_cast<uint32_t>(slots.size());
  rec.fill(removal_counts_, 0);
  rec.barrier();  // the work before, and the fill
  dispatch(rec, kernels_->edit, EditPush{n, s, 0u, 0u}, bindings, std::max(n, s));
  rec.barrier();
  record_precompute(rec, PrecomputePush{n, 1, 0, 0}, removal_list_, n);
  rec.barrier();
  dispatch(rec, kernels_->edit, EditPush{count_, 0u, 1u, 0u}, bindings, count_);
  rec.barrier();  // compute_forces() records into the same command buffer
  compute_forces();
  removal_counts_.invalidate();
  uint32_t counts[2];
  std::memcpy(counts, removal_counts_.mapped(), sizeof counts);
  regularised_ = counts[0];
  edited_ = counts[1];
}

// One submission: the edited flags, weights and the touched list copied up from a persistent
// upload buffer, the precompute over the list, and the flags it leaves read back (count_flags).
void GpuSolver::apply_edit(const std::vector<uint32_t>& flags, const std::vector<float>& weights,
                           const std::vector<uint32_t>& touched) {
  const VkDeviceSize flag_bytes = flags.size() * 4, weight_bytes = weights.size() * 4,
                     list_bytes = touched.size() * 4;
  if (flags.size() != count_ || weights.size() != pairs_)
    throw std::logic_error("GpuSolver::apply_edit: flags or weights of another size");
  if (edit_upload_.size() < flag_bytes + weight_bytes + list_bytes)
    edit_upload_ =
        Buffer(*ctx_, flag_bytes + weight_bytes + list_bytes, MemoryIntent::Upload, "edit upload");
  if (edit_readback_.size() < flag_bytes)
    edit_readback_ = Buffer(*ctx_, flag_bytes, MemoryIntent::Readback, "edit read-back");
  if (list_.size() < list_bytes)
    list_ = Buffer(*ctx_, list_bytes, MemoryIntent::Device, "precompute list");
  auto* up = static_cast<char*>(edit_upload_.mapped());
  std::memcpy(up, flags.data(), flag_bytes);
  std::memcpy(up + flag_bytes, weights.data(), weight_bytes);
  std::memcpy(up + flag_bytes + weight_bytes, touched.data(), list_bytes);
  Recorder& rec = *rec_[0];
  rec.barrier();
  rec.copy(edit_upload_, flags_, flag_bytes, 0, 0);
  weight_.record_copy_from(rec, edit_upload_, flag_bytes);
  if (list_bytes > 0) rec.copy(edit_upload_, list_, list_bytes, flag_bytes + weight_bytes, 0);
  rec.barrier();
  if (!touched.empty()) {
    record_precompute(rec, PrecomputePush{uint32_t(touched.size()), 1, 0, 0}, list_,
                      uint32_t(touched.size()));
    rec.barrier();
  }
  rec.copy(flags_, edit_readback_, flag_bytes, 0, 0);
  rec.submit_and_wait();
  edit_readback_.invalidate();
  count_flags(static_cast<const uint32_t*>(edit_readback_.mapped()));
}

}  // namespace phyxel::gpu
