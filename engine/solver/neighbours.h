// Rest-state neighbour lists (total Lagrangian): found once by spatial hashing, symmetric,
// sorted by index, within one object only. Compressed rows: the neighbours of phyxel i are
// index[offset[i] .. offset[i+1]).
#pragma once

#include <cstdint>
#include <vector>

#include "engine/sampling/phyxel_set.h"

namespace phyxel {

struct NeighbourLists {
  std::vector<uint32_t> offset;  // size N + 1
  std::vector<uint32_t> index;   // size offset[N]

  uint32_t count(size_t i) const { return offset[i + 1] - offset[i]; }
};

// Pairs (i, j), i != j, of the same object with |x0_j - x0_i|^2 < h^2 (1 - 1e-9), h the
// object's support radius.
// Phyxels flagged kRemoved get no neighbours and are no one's neighbour.
NeighbourLists find_rest_neighbours(const PhyxelSet& set);

}  // namespace phyxel
