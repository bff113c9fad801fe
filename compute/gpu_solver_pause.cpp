// GpuSolver's pauses inside an advance (advance_paused): the state a pause shows, copied aside
// inside the submission that runs past it, so that a frame drawn there does not end the
// submission (docs/performance-log.md, "The breast's frames: the drawing, not the pause").
#include <cstdlib>
#include <cstring>

#include "compute/gpu_solver.h"

namespace phyxel::gpu {

bool pause_snapshots_allowed() {
  const char* text = std::getenv("PHYXEL_FRAME_PAUSE");
  return text == nullptr || std::strcmp(text, "split") != 0;
}

void GpuSolver::record_pause_snapshot(Recorder& rec, int from) {
  if (!snap_disp_) snap_disp_ = Buffer(*ctx_, disp_[0].size(), MemoryIntent::Device, "pause u");
  // The sever and tear passes zero pair weights within the advance; else they stay as they are.
  snapshot_weights_ = (cutting_ || tearing_) && pairs_ > 0;
  if (snapshot_weights_ && snap_weight_.lo_buffer().size() != weight_.lo_buffer().size())
    snap_weight_ =
        PairBuffer(*ctx_, pairs_, weight_.lo_buffer().size() / sizeof(float), "pause pair weight");
  rec.barrier();  // the passes that wrote them
  rec.copy(disp_[from], snap_disp_);
  if (snapshot_weights_) {
    rec.copy(weight_.lo_buffer(), snap_weight_.lo_buffer());
    if (weight_.hi_buffer() != nullptr) rec.copy(*weight_.hi_buffer(), *snap_weight_.hi_buffer());
  }
  rec.barrier();  // before the next passes write them
}

void GpuSolver::pause_at(const std::function<void(int64_t)>& at, int64_t k, int shown) {
  shown_ = shown;
  try {
    at(k);
  } catch (...) {
    shown_ = 0;
    throw;
  }
  shown_ = 0;
}

}  // namespace phyxel::gpu
