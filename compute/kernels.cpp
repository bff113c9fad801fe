#include "compute/kernels.h"

#include <cstdint>

#include "phyxel_spv/axpy.spv.h"
#include "phyxel_spv/iota.spv.h"

namespace phyxel::gpu {

CoreKernels::CoreKernels(Context& ctx)
    : iota(ctx, PHYXEL_SHADER(iota), 1, sizeof(layout::IotaPush)),
      axpy(ctx, PHYXEL_SHADER(axpy), 2, sizeof(layout::AxpyPush)) {}

}  // namespace phyxel::gpu
