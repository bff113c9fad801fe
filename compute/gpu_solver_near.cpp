// GpuSolver: aspiration's reads without the whole state. After each tool chunk the aspirator
// needs u and the principal stress of the phyxels near a mouth (read_near), and after an event
// u of the neighbours of what it took (read_displacements): solver_near selects them in a box
// (modes 0 and 1, tool_broad_scan between) or gathers them by id (mode 2) and writes them
// straight into read-back buffers. One submission each; 20 bytes per phyxel back, instead of
// the 20 bytes per phyxel of the whole state and a host pass over it. After prefetch_near the
// next advance records read_near's passes at the end of its last submission instead.
#include <cstring>
#include <stdexcept>
#include <string>

#include "compute/gpu_solver.h"
#include "compute/gpu_solver_kernels.h"

namespace phyxel::gpu {

using namespace layout;

void GpuSolver::ensure_near_buffers() {
  if (near_ids_) return;
  const uint32_t wg = kernels_->near.workgroup_size()[0];
  const uint64_t groups = std::max<uint64_t>((uint64_t{count_} + wg - 1) / wg, 1);
  const uint64_t n = std::max<uint64_t>(count_, 1);
  near_groups_ = Buffer(*ctx_, groups * 4, MemoryIntent::Device, "near: hits per workgroup");
  // tool_broad_scan writes a SeverGroups after the count too (unread here).
  near_count_ = Buffer(*ctx_, sizeof(ContactCount) + sizeof(SeverGroups), MemoryIntent::Readback,
                       "near: count");
  near_ids_ = Buffer(*ctx_, n * 4, MemoryIntent::Readback, "near: ids");
  near_state_ = Buffer(*ctx_, n * sizeof(vec4), MemoryIntent::Readback, "near: u, principal");
}

void GpuSolver::record_near(Recorder& rec, NearPush push) {
  push.principal = principal_ ? 1u : 0u;
  // Without the principal stress a buffer of the right kind stands in (not read).
  const Buffer& principal = principal_ ? principal_stress_ : disp_[0];
  const Buffer& ids = push.mode == 2 ? near_upload_ : near_ids_;
  const uint32_t elements =
      push.mode == 2 ? push.count : push.groups * kernels_->near.workgroup_size()[0];
  dispatch(rec, kernels_->near, push,
           {{"Rest", rest_},
            {"Disp", disp_[0]},
            {"Principal", principal},
            {"Group", near_groups_},
            {"Ids", ids},
            {"Out", near_state_}},
           elements);
}

void GpuSolver::prefetch_near(const Bounds& box) {
  near_box_ = box;
  near_asked_ = true;
}

void GpuSolver::record_near_box(Recorder& rec, const Bounds& box) {
  const uint32_t wg = kernels_->near.workgroup_size()[0];
  const uint32_t groups = (count_ + wg - 1) / wg;
  NearPush push{{float(box.min.x()), float(box.min.y()), float(box.min.z()), 0.0f},
                {float(box.max.x()), float(box.max.y()), float(box.max.z()), 0.0f},
                count_,
                0u,
                groups,
                0u};
  rec.barrier();  // what ran before (the last substep, an edit's forces) wrote u or the stress
  record_near(rec, push);
  rec.barrier();
  BroadPhasePush scan{};
  scan.groups = groups;
  dispatch(rec, kernels_->broad_scan, scan, {{"Group", near_groups_}, {"Count", near_count_}},
           kernels_->broad_scan.workgroup_size()[0]);
  rec.barrier();
  push.mode = 1;
  record_near(rec, push);
}

NearState GpuSolver::read_near(const PhyxelSet& set, const Bounds& box) {
  // Recorded at the end of the last advance for this box, and nothing since (settle()).
  const bool prefetched = near_ready_ && box.min == near_box_.min && box.max == near_box_.max;
  settle_for_read();  // a read: the prefetched checks stay
  if (set.size() != count_)
    throw std::invalid_argument("GpuSolver::read_near: the set has " + std::to_string(set.size()) +
                                " phyxels, the solver " + std::to_string(count_));
  NearState near;
  if (count_ == 0 || box.empty()) return near;
  ensure_near_buffers();
  if (!prefetched) {
    Recorder& rec = *rec_[0];
    record_near_box(rec, box);
    rec.submit_and_wait();
  }
  near_count_.invalidate();
  ContactCount count;
  std::memcpy(&count, near_count_.mapped(), sizeof count);
  const size_t hits = count.total;
  near_ids_.invalidate();
  near_state_.invalidate();
  const auto* ids = static_cast<const uint32_t*>(near_ids_.mapped());
  const auto* state = static_cast<const vec4*>(near_state_.mapped());
  near.ids.assign(ids, ids + hits);
  near.displacement.resize(hits);
  if (principal_) near.principal.resize(hits);
  for (size_t k = 0; k < hits; ++k) {
    near.displacement[k] = Vec3(state[k].x, state[k].y, state[k].z);
    if (principal_) near.principal[k] = state[k].w;
  }
  return near;
}

std::vector<Vec3> GpuSolver::read_displacements(const std::vector<uint32_t>& ids) {
  settle_for_read();
  std::vector<Vec3> out(ids.size());
  if (ids.empty()) return out;
  for (const uint32_t i : ids)
    if (i >= count_)
      throw std::out_of_range("GpuSolver::read_displacements: no phyxel " + std::to_string(i));
  ensure_near_buffers();
  const uint64_t bytes = ids.size() * sizeof(uint32_t);
  if (near_upload_.size() < bytes)
    near_upload_ = Buffer(*ctx_, std::max<uint64_t>(bytes, 2 * near_upload_.size()),
                          MemoryIntent::Upload, "near: ids to gather");
  std::memcpy(near_upload_.mapped(), ids.data(), bytes);
  Recorder& rec = *rec_[0];
  rec.barrier();
  record_near(rec, NearPush{{}, {}, static_cast<uint32_t>(ids.size()), 2u, 0u, 0u});
  rec.submit_and_wait();
  near_state_.invalidate();
  const auto* state = static_cast<const vec4*>(near_state_.mapped());
  for (size_t k = 0; k < ids.size(); ++k) out[k] = Vec3(state[k].x, state[k].y, state[k].z);
  return out;
}

}  // namespace phyxel::gpu
