// GpuSolver: the graspers with CpuSolver's semantics (engine/solver/cpu_solver_grasp.cpp,
// engine/solver/grasper.h). Which substeps close, hold or open a tool's jaws follows from the
// motion table alone, so the host decides while recording: in the substep the jaws close it
// records tool_grasp's capture (one workgroup over the contact candidates, ascending, into the
// tool's region of the grip buffer, with the count and indirect dispatch of the hold), and in
// every substep they are closed the hold (indirect, over the grip) and the reduction of the
// grip's force into the tool's sample. Jaws that open record nothing more: the grip is
// forgotten. Nothing is read back during the advance; the held count comes back in the samples
// (second row, z). Scenes without a grasper allocate and record none of it. With one grasper
// and tool_contact summing its own samples, the hold of jaws closed before the substep is
// tool_contact's (grasp_in_contact), which saves the hold's dispatch and barrier.
#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "compute/gpu_solver.h"
#include "compute/gpu_solver_kernels.h"

namespace phyxel::gpu {

using namespace layout;

void GpuSolver::prepare_grasping() {
  grasping_ = std::any_of(tools_.begin(), tools_.end(),
                          [](const ContactTool& t) { return t.grasp.grasps(); });
  grip_closed_.assign(tools_.size(), 0);
  if (!grasping_) return;
  Context& ctx = *ctx_;
  const uint64_t entries = uint64_t{std::max<uint32_t>(count_, 1)} * tools_.size();
  if (!grip_ || grip_.size() < entries * sizeof(GraspEntry)) {
    grip_ = Buffer(ctx, entries * sizeof(GraspEntry), MemoryIntent::Device, "grasper grips");
    grip_force_ = Buffer(ctx, entries * sizeof(vec4), MemoryIntent::Device, "grasper grip forces");
    grip_count_ = Buffer(ctx, tools_.size() * sizeof(ContactCount), MemoryIntent::Device,
                         "grasper grip counts", VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
    grip_of_ = Buffer(ctx, entries * sizeof(uint32_t), MemoryIntent::Device,
                      "grasper grip entry per phyxel");
  }
  rec_[0]->fill(grip_count_, 0);  // submitted by set_tools with the contact flags' reset
  rec_[0]->fill(grip_of_, ~0u);
}

uint32_t GpuSolver::grasp_in_contact(int64_t step) const {
  if (!grasping_ || !options_.grasp_in_contact || !contact_fused()) return kContactNoGrasp;
  uint32_t only = kContactNoGrasp;
  for (uint32_t t = 0; t < tools_.size(); ++t) {
    if (!tools_[t].grasp.grasps()) continue;
    if (only != kContactNoGrasp) return kContactNoGrasp;  // two graspers: their own passes
    only = t;
  }
  // Jaws that close in this substep capture after the contact: their own passes.
  const size_t row = contact_motion_row(step);
  if (!grip_closed_[only] || !motion_[row * tools_.size() + only].grip_closed)
    return kContactNoGrasp;
  return only;
}

bool GpuSolver::grasp_passes_left(int64_t step, uint32_t in_contact) {
  const size_t nt = tools_.size();
  const size_t row = contact_motion_row(step);
  bool left = false;
  for (uint32_t t = 0; t < nt; ++t) {
    if (!tools_[t].grasp.grasps()) continue;
    if (!motion_[row * nt + t].grip_closed)
      grip_closed_[t] = 0;  // open: the grip is forgotten
    else if (t != in_contact)
      left = true;
  }
  return left;
}

void GpuSolver::record_grasp(Recorder& rec, int64_t step, float dt, const Buffer& disp,
                             uint32_t in_contact) {
  const uint32_t nt = static_cast<uint32_t>(tools_.size());
  const uint64_t k = motion_step_ + uint64_t(step);  // as record_contact
  const uint32_t row = static_cast<uint32_t>(std::min<uint64_t>(k, motion_steps_ - 1));
  const uint32_t wg = kernels_->grasp.workgroup_size()[0];
  for (uint32_t t = 0; t < nt; ++t) {
    const Grasp& grasp = tools_[t].grasp;
    if (!grasp.grasps() || t == in_contact) continue;
    if (!motion_[size_t(row) * nt + t].grip_closed) {  // open: the grip is forgotten
      grip_closed_[t] = 0;
      continue;
    }
    GraspPush push{{contact_origin_.x, contact_origin_.y, contact_origin_.z, float(grasp.reach)},
                   dt,
                   t,
                   nt,
                   row,
                   k >= motion_steps_ ? 1u : 0u,
                   count_,
                   kGraspCapture,
                   static_cast<uint32_t>(step)};
    auto pass = [&](uint32_t mode, uint32_t elements) {
      push.mode = mode;
      const std::initializer_list<BufferRef> bindings = {{"List", candidate_list_},
                                                         {"Candidates", contact_count_},
                                                         {"Rest", rest_},
                                                         {"Disp", disp},
                                                         {"Vel", vel_},
                                                         {"Ext", ext_},
                                                         {"Flags", flags_},
                                                         {"Motion", motion_table_},
                                                         {"Grip", grip_},
                                                         {"Count", grip_count_},
                                                         {"Force", grip_force_},
                                                         {"Samples", samples_buffer_},
                                                         {"Done", contact_done_},
                                                         {"GripOf", grip_of_}};
      if (elements > 0)
        dispatch(rec, kernels_->grasp, push, bindings, elements);
      else
        dispatch_indirect(rec, kernels_->grasp, push, bindings, grip_count_,
                          t * sizeof(ContactCount) + offsetof(ContactCount, groups_x));
    };
    if (!grip_closed_[t]) {  // closing: take the candidates within reach
      pass(kGraspCapture, wg);
      rec.indirect_barrier();
      grip_closed_[t] = 1;
    }
    pass(kGraspHoldReduce, 0);
    // Every mode binds the grip counts as writable: the next substep's hold reads them as its
    // indirect dispatch.
    rec.indirect_barrier();
  }
}

std::vector<uint32_t> GpuSolver::held_phyxels(size_t tool) {
  settle();
  if (tool >= grip_closed_.size() || !grip_closed_[tool]) return {};
  const auto count = download<ContactCount>(*ctx_, grip_count_, 1, tool * sizeof(ContactCount));
  if (count.front().total == 0) return {};
  const auto entries = download<GraspEntry>(*ctx_, grip_, count.front().total,
                                            tool * uint64_t{count_} * sizeof(GraspEntry));
  std::vector<uint32_t> held;
  for (const GraspEntry& e : entries)
    if (!(phyxel_flags_.at(e.phyxel.x) & kRemoved)) held.push_back(e.phyxel.x);
  return held;
}

// The grips as they are (offsets float32, converted exactly; removed phyxels stay, as the hold
// pass skips them), for checkpoints.
std::vector<Grip> GpuSolver::grips() {
  settle();
  std::vector<Grip> grips(tools_.size());
  for (size_t t = 0; t < grips.size() && grasping_; ++t) {
    if (!grip_closed_[t]) continue;
    grips[t].closed = true;
    const auto count = download<ContactCount>(*ctx_, grip_count_, 1, t * sizeof(ContactCount));
    if (count.front().total == 0) continue;
    const auto entries = download<GraspEntry>(*ctx_, grip_, count.front().total,
                                              t * uint64_t{count_} * sizeof(GraspEntry));
    for (const GraspEntry& e : entries)
      grips[t].held.push_back({e.phyxel.x, Vec3(e.offset.x, e.offset.y, e.offset.z)});
  }
  return grips;
}

// Checkpointed grips back into the grip buffers, with the counts and indirect dispatch the
// capture would have written (after set_tools).
void GpuSolver::restore_grips(const std::vector<Grip>& grips) {
  settle();
  if (grips.size() != tools_.size())
    throw std::invalid_argument("GpuSolver::restore_grips: " + std::to_string(grips.size()) +
                                " grips for " + std::to_string(tools_.size()) + " tools");
  const uint32_t wg = kernels_->grasp.workgroup_size()[0];
  for (size_t t = 0; t < grips.size(); ++t) {
    if (!grips[t].closed) continue;
    if (!tools_[t].grasp.grasps() || grips[t].held.size() > count_)
      throw std::invalid_argument("GpuSolver::restore_grips: tool " + std::to_string(t) +
                                  " cannot hold that grip");
    std::vector<GraspEntry> entries;
    for (const GripEntry& e : grips[t].held) {
      if (e.phyxel >= count_)
        throw std::invalid_argument("GpuSolver::restore_grips: no phyxel " +
                                    std::to_string(e.phyxel));
      entries.push_back({{float(e.offset.x()), float(e.offset.y()), float(e.offset.z()), 0.0f},
                         {e.phyxel, 0u, 0u, 0u}});
    }
    const uint32_t total = static_cast<uint32_t>(entries.size());
    const uint32_t groups = (total + wg - 1) / wg;
    const std::vector<ContactCount> count = {
        {total, std::min(groups, 65535u), (groups + 65534u) / 65535u, 1u}};
    std::vector<uint32_t> grip_of(count_, ~0u);  // as the capture writes it
    for (uint32_t e = 0; e < total; ++e) grip_of[entries[e].phyxel.x] = e;
    if (!entries.empty()) upload(*ctx_, grip_, entries, t * uint64_t{count_} * sizeof(GraspEntry));
    upload(*ctx_, grip_count_, count, t * sizeof(ContactCount));
    if (count_ > 0) upload(*ctx_, grip_of_, grip_of, t * uint64_t{count_} * sizeof(uint32_t));
    grip_closed_[t] = 1;
  }
}

}  // namespace phyxel::gpu
