// GpuSolver: the tool contact inside the force pass where nothing tears (contact_in_force_ with
// a blade without a threshold and at most one grasper; gpu_solver_tearing.cpp has the tearing
// case). solver_force_contact does, after each phyxel's drift of substep s, tool_contact's work
// of substep s + 1 on it: the contact of a candidate, the grasper's hold of a held phyxel, and
// the hold of the held phyxels outside the force list; it empties the sever's dirty list. A
// substep whose jaws close keeps tool_contact and the grasp's passes (the capture reads the
// candidates after their contact). The felt forces go into rows that record_contact_rows sums
// after the advance, per run of fused substeps; the grip's forces of a fused substep, which
// the next force pass overwrites, are summed into a grip row beside the next sever (or stress
// pass), then subtracted from the sample after its contacts' sum, as tool_contact's last
// workgroup does: the same bits, in the CPU's order.
#include <algorithm>

#include "compute/gpu_solver.h"
#include "compute/gpu_solver_kernels.h"

namespace phyxel::gpu {

using namespace layout;

bool GpuSolver::contact_fusable(int64_t step) const {
  if (!grasping_) return true;
  const size_t nt = tools_.size();
  const size_t row = contact_motion_row(step);
  for (size_t t = 0; t < nt; ++t)
    if (tools_[t].grasp.grasps() && motion_[row * nt + t].grip_closed && !grip_closed_[t])
      return false;  // the jaws close: the capture's own pass
  return true;
}

uint32_t GpuSolver::fuse_contact(int64_t step) {
  const uint32_t grasp = grasp_in_contact(step);
  grasp_passes_left(step, grasp);  // forgets the grips of jaws that open (none closes here)
  sums_pending_ = -1;
  if (contact_runs_.empty() || contact_runs_.back().second != step)
    contact_runs_.push_back({step, step});
  ++contact_runs_.back().second;
  return grasp;
}

void GpuSolver::record_force_contact(Recorder& rec, float dt, const Buffer& in, const Buffer& out,
                                     int64_t step, uint32_t grasp) {
  const uint32_t n = static_cast<uint32_t>(force_count_);
  const StepPush sp = push(n, dt, kForceKickDrift, lanes_for(Gather::Force, n));
  ForceTearPush pc{};
  pc.count = sp.count;
  pc.dt = sp.dt;
  pc.mode = sp.mode;
  pc.weights = sp.weights;
  pc.lanes = sp.lanes;
  pc.contact_origin = contact_origin_;
  pc.contact_row = static_cast<uint32_t>(step);
  pc.contact_motion = contact_motion_row(step);
  pc.contact_hold = contact_hold(step);
  pc.contact_tools = static_cast<uint32_t>(tools_.size());
  pc.contact_stride = partial_capacity() * PHYXEL_WORKGROUP_SIZE;
  pc.contact_fuse = kForceContact | (cut_dirty_ ? kForceContactDirtyReset : 0u);
  pc.contact_grasp = grasp;
  pc.grip_capacity = count_;
  const bool grip = grasp != kContactNoGrasp;
  // Stand-ins where there is no dirty list or no hold (unread, 32 bytes at least).
  dispatch(rec, kernels_->force_contact, pc,
           {{"Offset", nbr_offset_},
            {"IndexLo", nbr_index_.lo()},
            {"WeightLo", weight_.lo()},
            {"Local", local_},
            {"DispIn", in},
            {"DispOut", out},
            {"Stress", stress_},
            {"Vel", vel_},
            {"Force", force_},
            {"Ext", force_ext()},
            {"Flags", flags_},
            {"Classes", classes_},
            {"List", force_list_},
            {"IndexHi", nbr_index_.hi()},
            {"WeightHi", weight_.hi()},
            {"Rest", rest_},
            {"Slot", candidate_slot_},
            {"Count", contact_count_},
            {"Tools", tool_shapes_},
            {"Motion", motion_table_},
            {"Rows", contact_rows_},
            {"Contact", contact_flag_},
            {"Dirty", cut_dirty_ ? cut_dirty_ : contact_done_},
            {"Grip", grip ? grip_ : contact_count_},
            {"Held", grip ? grip_count_ : contact_count_},
            {"GripForce", grip ? grip_force_ : row_partials_},
            {"GripOf", grip ? grip_of_ : contact_done_},
            {"InForce", in_force_bits_}},
           n * pc.lanes);
}

void GpuSolver::record_grip_row(Recorder& rec, int64_t step, uint32_t grasp) {
  const uint32_t nt = static_cast<uint32_t>(tools_.size());
  part_begin(rec, "contact: grip");
  // Buffers neither the sever nor the stress pass beside it touch (Flags: a stand-in, unread).
  dispatch(rec, kernels_->contact_reduce,
           ContactReducePush{0u, nt, partial_capacity(), static_cast<uint32_t>(step),
                             kContactReduceGripRow, grasp, count_},
           {{"Force", candidate_force_},
            {"Samples", grip_rows_},
            {"Count", contact_count_},
            {"List", candidate_list_},
            {"Flags", candidate_list_},
            {"Partials", candidate_force_},  // unwritten
            {"Held", grip_count_},
            {"GripForce", grip_force_}},
           kernels_->contact_reduce.workgroup_size()[0]);
  part_end(rec);
}

void GpuSolver::record_fused_rows(Recorder& rec) {
  for (size_t r = 0; r < contact_runs_.size(); ++r) {
    if (r > 0) rec.barrier();  // the same partials' buffer
    record_contact_rows(rec, contact_runs_[r].first, contact_runs_[r].second);
  }
  contact_runs_.clear();
}

}  // namespace phyxel::gpu
