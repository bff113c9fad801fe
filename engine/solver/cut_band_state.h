// What a checkpoint keeps of a solver's SCNI band (CutBand, cut_band.h; engine/run/checkpoint.h):
// enough to rebuild the same cells bit for bit. Empty where the scene has no band.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "engine/geometry/vec3.h"

namespace phyxel {

struct CutBandState {
  std::vector<std::array<Vec3, 4>> quads;  // the cut surface, in the order stored
  uint64_t quads_built = 0;                // quads whose cells were looked for
  uint64_t quads_before_chunk = 0;         // quads stored before the current chunk
  // Per cell, in the band's order: its phyxel, whether quads reached it since it was built, and
  // how many quads were stored when it was built (0: not built; its boxes saw those quads).
  std::vector<uint32_t> phyxel;
  std::vector<uint8_t> dirty;
  std::vector<uint64_t> built_with;
};

}  // namespace phyxel
