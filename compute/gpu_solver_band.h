// GpuSolver's SCNI band (compute/gpu_solver_band.cpp): CutBand's cells on the host, their
// boxes in float on the GPU, and the two passes that integrate them. Made only for a scene
// with cut_band > 0. Private to compute/gpu_solver*.cpp.
#pragma once

#include <cstdint>

#include "compute/buffer.h"
#include "compute/pipeline.h"
#include "engine/solver/cut_band.h"

namespace phyxel::gpu {

struct GpuBand {
  GpuBand(Context& ctx, const PhyxelSet& set, const std::vector<double>& volume);
  CutBand cells;
  Pipeline stress, force;  // band_stress.comp, band_force.comp (layout_band.h)
  Buffer boxes, coeff, box_stress, nodes, entries, ext;
  uint32_t box_count = 0, node_count = 0;  // 0 until a cell is built
};

}  // namespace phyxel::gpu
