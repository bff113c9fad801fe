// GpuSolver: tearing with CpuSolver's semantics (engine/solver/cpu_solver_tearing.cpp,
// engine/solver/tearing.h). Per substep, in the same command buffer: the dirty list's count
// reset (unless tool_contact emptied it), then solver_force_tear in place of the force pass: the
// forces of the intact pairs, then the tear test over the stress list (on the u the stress pass
// read), whose last workgroup reruns the precompute of the phyxels it put in the dirty list. The
// torn pairs join the cut log, read back once per advance (finish_cutting). With
// contact_in_force_ the pass also does the next substep's tool contact after the drift
// (force_contact.glsl) and empties the dirty list in its last workgroup, as tool_contact did.
#include <algorithm>

#include "compute/gpu_solver.h"
#include "compute/gpu_solver_kernels.h"

namespace phyxel::gpu {

using namespace layout;

void GpuSolver::set_tearing(bool on) {
  settle();
  if (on == tearing_) return;
  if (!on) {
    tearing_ = false;  // the tensor buffer stays for a later turn on
    return;
  }
  if (!cauchy_)
    cauchy_ = Buffer(*ctx_, std::max<uint64_t>(count_, 1) * 2 * sizeof(vec4), MemoryIntent::Device,
                     "Cauchy stress");
  prepare_cutting();  // the dirty list and the log
  Recorder& rec = *rec_[0];
  rec.fill(cauchy_, 0);  // as the CPU's: 0 until a phyxel is in the stress pass
  rec.barrier();         // set_principal_stress and compute_forces record after it
  tearing_ = true;
  if (principal_) {
    compute_forces();  // the tensors for the current u
  } else {
    set_principal_stress(true);  // zeroes the principal buffer, then computes the forces
  }
}

void GpuSolver::record_force_tear(Recorder& rec, uint32_t mode, float dt, const Buffer& in,
                                  const Buffer& out, int64_t contact_step) {
  const uint32_t n = static_cast<uint32_t>(force_count_);
  const uint32_t tear_only = static_cast<uint32_t>(tear_only_host_.size());
  // The force pass's lanes: the tear test shares its invocations.
  const StepPush step = push(n, dt, mode, lanes_for(Gather::Force, n));
  ForceTearPush pc{};  // no contact unless set below
  pc.count = step.count;
  pc.dt = step.dt;
  pc.mode = step.mode;
  pc.weights = step.weights;
  pc.lanes = step.lanes;
  pc.tear_only = tear_only;
  pc.log_capacity = log_capacity_;
  pc.weakest = weakest_tear_;
  // Unbound without the contact (never read then): any buffer of the pass.
  const Buffer* slot = &flags_;
  const Buffer* count = &flags_;
  const Buffer* tools = &flags_;
  const Buffer* motion = &flags_;
  const Buffer* rows = &force_;
  const Buffer* contact = &flags_;
  if (contact_step >= 0) {
    pc.contact_origin = contact_origin_;
    pc.contact_row = static_cast<uint32_t>(contact_step);
    pc.contact_motion = contact_motion_row(contact_step);
    pc.contact_hold = contact_hold(contact_step);
    pc.contact_tools = static_cast<uint32_t>(tools_.size());
    pc.contact_stride = partial_capacity() * PHYXEL_WORKGROUP_SIZE;
    pc.contact_fuse = kForceContact | kForceContactDirtyReset;
    slot = &candidate_slot_;
    count = &contact_count_;
    tools = &tool_shapes_;
    motion = &motion_table_;
    rows = &contact_rows_;
    contact = &contact_flag_;
  }
  dispatch(rec, kernels_->force_tear, pc,
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
            {"Principal", principal_stress_},
            {"Cauchy", cauchy_},
            {"Dirty", cut_dirty_},
            {"Log", cut_log_},
            {"Ainv", ainv_},
            {"Resid", resid_},
            {"Done", cut_done_},
            {"Slot", *slot},
            {"Count", *count},
            {"Tools", *tools},
            {"Motion", *motion},
            {"Rows", *rows},
            {"Contact", *contact}},
           (n + tear_only) * pc.lanes);
}

}  // namespace phyxel::gpu
