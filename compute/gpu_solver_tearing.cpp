// GpuSolver: tearing with CpuSolver's semantics (engine/solver/cpu_solver_tearing.cpp,
// engine/solver/tearing.h). Per substep, in the same command buffer: the dirty list's count
// reset (unless tool_contact emptied it), then solver_force_tear in place of the force pass: the
// forces of the intact pairs, then the tear test over the stress list (on the u the stress pass
// read), whose last workgroup reruns the precompute of the phyxels it put in the dirty list. The
// torn pairs join the cut log, read back once per advance (finish_cutting).
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
                                  const Buffer& out) {
  const uint32_t n = static_cast<uint32_t>(force_count_);
  const uint32_t tear_only = static_cast<uint32_t>(tear_only_host_.size());
  // The force pass's lanes: the tear test shares its invocations.
  const StepPush step = push(n, dt, mode, lanes_for(Gather::Force, n));
  const ForceTearPush pc{step.count, step.dt,   step.mode,     step.weights,
                         step.lanes, tear_only, log_capacity_, weakest_tear_};
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
            {"Ext", ext_},
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
            {"Done", cut_done_}},
           (n + tear_only) * pc.lanes);
}

}  // namespace phyxel::gpu
