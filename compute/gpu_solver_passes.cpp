// GpuSolver: pass selection, sleeping and load changes, with CpuSolver's semantics
// (engine/solver/cpu_solver.cpp, build_pass_lists, set_object_awake, set_external_forces).
//
// The lists are built on the host (from the engine flags, the awake objects and the CSR, all
// kept on the host) whenever they change, which is rare (a sleep, a wake, --no-skip, a cut),
// and uploaded; the step passes read their phyxel index from them (solver_kick_drift and
// solver_force from the force list, solver_stress from the stress list) and are dispatched
// over the list's length. The queries (energies, check, von Mises) still visit every phyxel.
// A removal updates the lists in place (remove_from_pass_lists) instead of rebuilding them.
#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

#include "compute/gpu_solver.h"
#include "compute/gpu_solver_kernels.h"

namespace phyxel::gpu {

using namespace layout;

void GpuSolver::build_pass_lists() {
  const size_t n = count_;
  const NeighbourLists& nbr = neighbours_;
  in_force_.assign(n, 0);
  stress_refs_.assign(n, 0);
  for (size_t i = 0; i < n; ++i) {
    if (!awake_[object_[i]] || (phyxel_flags_[i] & kRemoved)) continue;
    // Without selection, fixed phyxels get forces too (reactions; they do not move).
    if (!select_ || !(phyxel_flags_[i] & kFixed)) {
      in_force_[i] = 1;
      if (!select_) continue;
      // Pairs to removed phyxels stay in the CSR with weight 0 (remove_phyxels); the CPU's
      // lists of a cut set have no such pairs, so they add nothing (in_stress tests it).
      for (uint32_t k = nbr.offset[i]; k < nbr.offset[i + 1]; ++k) ++stress_refs_[nbr.index[k]];
    }
  }
  force_list_host_.clear();
  stress_list_host_.clear();
  for (size_t i = 0; i < n; ++i) {
    if (in_force_[i]) force_list_host_.push_back(static_cast<uint32_t>(i));
    if (in_stress(i)) stress_list_host_.push_back(static_cast<uint32_t>(i));
  }
  upload_pass_lists();
}

// A phyxel is in the stress pass where it is in the force pass or, with selection, in the
// neighbourhood of one that is, and not removed.
bool GpuSolver::in_stress(size_t i) const {
  return !(phyxel_flags_[i] & kRemoved) && (in_force_[i] || (select_ && stress_refs_[i] > 0));
}

// After a removal the lists only shrink: the removed phyxels leave them, and their force-list
// neighbours' references go with them. O(removed x neighbours) plus one filter of each list
// (the full build walks every pair: O(N + pairs) on the host per event).
void GpuSolver::remove_from_pass_lists(const std::vector<uint32_t>& ids) {
  const NeighbourLists& nbr = neighbours_;
  for (uint32_t i : ids) {
    if (!in_force_[i]) continue;  // not in the force list, or listed twice
    in_force_[i] = 0;
    if (!select_) continue;
    for (uint32_t k = nbr.offset[i]; k < nbr.offset[i + 1]; ++k) --stress_refs_[nbr.index[k]];
  }
  auto drop = [](std::vector<uint32_t>& list, auto&& keep) {
    list.erase(std::remove_if(list.begin(), list.end(), [&](uint32_t i) { return !keep(i); }),
               list.end());
  };
  drop(force_list_host_, [&](uint32_t i) { return in_force_[i] != 0; });
  drop(stress_list_host_, [&](uint32_t i) { return in_stress(i); });
  upload_pass_lists();
}

// Both lists through a persistent upload buffer (removals change them dozens of times a run),
// recorded ahead of the forces that every caller recomputes next (compute_forces submits them);
// while the solver is being built, in a submission of their own. The force list's buffer holds
// after it the stress list's phyxels that it lacks (fixed ones beside moving ones), whose pairs
// solver_force_tear tests too: stress + force + those <= 2 N entries.
void GpuSolver::upload_pass_lists() {
  tear_only_host_.clear();
  for (const uint32_t i : stress_list_host_)
    if (!in_force_[i]) tear_only_host_.push_back(i);
  const VkDeviceSize stress_bytes = stress_list_host_.size() * 4,
                     force_bytes = force_list_host_.size() * 4,
                     tear_bytes = tear_only_host_.size() * 4;
  if (stress_bytes + force_bytes > 0) {
    if (list_upload_.size() < stress_bytes + force_bytes)
      list_upload_ =
          Buffer(*ctx_, VkDeviceSize{count_} * 8, MemoryIntent::Upload, "pass list upload");
    auto* up = static_cast<char*>(list_upload_.mapped());
    std::memcpy(up, stress_list_host_.data(), stress_bytes);
    std::memcpy(up + stress_bytes, force_list_host_.data(), force_bytes);
    std::memcpy(up + stress_bytes + force_bytes, tear_only_host_.data(), tear_bytes);
    const uint64_t bits_bytes = stage_in_force_bits();
    auto record = [&](Recorder& rec) {
      rec.barrier();  // the passes that read the lists before
      if (stress_bytes > 0) rec.copy(list_upload_, stress_list_, stress_bytes, 0, 0);
      if (force_bytes + tear_bytes > 0)
        rec.copy(list_upload_, force_list_, force_bytes + tear_bytes, stress_bytes, 0);
      rec.copy(in_force_upload_, in_force_bits_, bits_bytes, 0, 0);
      rec.barrier();
    };
    if (rec_[0]) {
      record(*rec_[0]);
    } else {
      Recorder rec(*ctx_, "pass lists");
      record(rec);
      rec.submit_and_wait();
    }
  }
  stress_count_ = stress_list_host_.size();
  force_count_ = force_list_host_.size();
}

// A bit per phyxel, in the force list or not (solver_force_contact's hold outside the list),
// into its upload buffer: upload_pass_lists copies it with the lists. Returns its bytes.
uint64_t GpuSolver::stage_in_force_bits() {
  const uint64_t words = std::max<uint64_t>((uint64_t{count_} + 31) / 32, 8);
  if (!in_force_bits_ || in_force_bits_.size() < words * 4) {
    in_force_upload_ = Buffer(*ctx_, words * 4, MemoryIntent::Upload, "in force list bits upload");
    in_force_bits_ = Buffer(*ctx_, words * 4, MemoryIntent::Device, "in force list bits");
  }
  auto* bits = static_cast<uint32_t*>(in_force_upload_.mapped());
  std::fill(bits, bits + words, 0u);
  for (const uint32_t i : force_list_host_) bits[i / 32] |= 1u << (i % 32);
  return words * 4;
}

void GpuSolver::set_pass_selection(bool enabled) {
  settle();
  select_ = enabled;
  build_pass_lists();
  compute_forces();
}

void GpuSolver::set_object_awake(uint32_t object, bool awake) {
  settle();
  if (object >= awake_.size())
    throw std::out_of_range("GpuSolver::set_object_awake: no object " + std::to_string(object));
  if (bool(awake_[object]) == awake) return;
  awake_[object] = awake;
  build_pass_lists();
  // Sleeping objects take no contact: the chunk's candidates follow the awake objects.
  if (!tools_.empty() && motion_steps_ > 0) broad_pending_ = true;
  if (!awake && objects_[object].count > 0) {
    // An object's phyxels are one range of the per-phyxel buffers.
    Recorder& rec = *rec_[0];
    rec.fill(vel_, 0, uint64_t{objects_[object].first} * sizeof(vec4),
             uint64_t{objects_[object].count} * sizeof(vec4));
    rec.barrier();  // compute_forces() records into the same command buffer
  }
  compute_forces();
}

void GpuSolver::set_external_forces(const std::vector<Vec3>& loads) {
  settle();
  if (loads.size() != count_)
    throw std::invalid_argument("GpuSolver::set_external_forces: expected " +
                                std::to_string(count_) + " loads, got " +
                                std::to_string(loads.size()));
  std::vector<vec4> ext(count_);
  for (size_t i = 0; i < count_; ++i) {
    const Vec3 f = mass_[i] * gravity_ + loads[i];  // in double, then rounded, as the CPU's
    ext[i] = {float(f.x()), float(f.y()), float(f.z()), float(mass_[i])};
  }
  upload(*ctx_, ext_, ext);
  copy_band_ext();  // the band's copy starts from it
  compute_forces();
}

void GpuSolver::set_principal_stress(bool on) {
  settle();
  if (on == principal_) return;
  principal_ = on;
  if (!on) {  // the buffer stays for a later turn on; nothing records the pass
    tearing_ = false;
    return;
  }
  if (!principal_stress_)
    principal_stress_ = Buffer(*ctx_, std::max<uint64_t>(count_, 1) * sizeof(float),
                               MemoryIntent::Device, "largest principal stress");
  Recorder& rec = *rec_[0];
  rec.fill(principal_stress_, 0);  // as the CPU's: 0 until a phyxel is in the stress pass
  rec.barrier();                   // compute_forces() records into the same command buffer
  compute_forces();
}

}  // namespace phyxel::gpu
