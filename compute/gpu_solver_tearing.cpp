// GpuSolver: tearing with CpuSolver's semantics (engine/solver/cpu_solver_tearing.cpp,
// engine/solver/tearing.h). Per substep, after the force pass and in the same command buffer:
// the dirty list's count reset (unless tool_contact emptied it) and solver_tear over the stress
// list (on the u the stress pass read), whose last workgroup reruns the precompute of the phyxels
// it put in the dirty list. The torn pairs join the cut log, read back once per advance
// (finish_cutting).
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

void GpuSolver::record_tear(Recorder& rec, const Buffer& disp) {
  const uint32_t n = static_cast<uint32_t>(stress_count_);
  // tool_contact emptied the list in this substep unless a sever filled it after.
  if (!contact_fused() || cutting_) {
    part_begin(rec, "tear: reset");
    record_dirty_reset(rec);
    part_end(rec);
  }
  part_begin(rec, "tear: pairs");
  // Lanes as the stress pass's gather: a pass of a few thousand phyxels is latency-bound.
  const uint32_t lanes = lanes_for(Gather::Stress, n);
  dispatch(rec, kernels_->tear, TearPush{n, log_capacity_, weakest_tear_, lanes},
           {{"List", stress_list_},
            {"Rest", rest_},
            {"Disp", disp},
            {"Offset", nbr_offset_},
            {"IndexLo", nbr_index_.lo()},
            {"WeightLo", weight_.lo()},
            {"Flags", flags_},
            {"Classes", classes_},
            {"Principal", principal_stress_},
            {"Cauchy", cauchy_},
            {"Dirty", cut_dirty_},
            {"Log", cut_log_},
            {"IndexHi", nbr_index_.hi()},
            {"WeightHi", weight_.hi()},
            {"Local", local_},
            {"Ainv", ainv_},
            {"Resid", resid_},
            {"Done", cut_done_}},
           n * lanes);
  part_end(rec);
}

}  // namespace phyxel::gpu
