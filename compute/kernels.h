// The Vulkan core's own small kernels, which prove the chain (embedded SPIR-V → pipeline →
// dispatch → readback) and serve as examples for the solver passes.
#pragma once

#include "compute/pipeline.h"
#include "compute/shaders/layout.h"

namespace phyxel::gpu {

struct CoreKernels {
  explicit CoreKernels(Context& ctx);

  Pipeline iota;  // shaders/iota.comp: push layout::IotaPush, buffers {dst (uint)}
  Pipeline axpy;  // shaders/axpy.comp: push layout::AxpyPush, buffers {x, y (float)}
};

}  // namespace phyxel::gpu
