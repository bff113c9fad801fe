// What a cut removed (docs/cutting.md, "Resection"): the pieces the severed pairs have freed
// from everything fixed, and per inclusion (a tumour) how much of it they carry, how much
// healthy tissue comes with it, and whether it comes out whole.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "engine/sampling/phyxel_set.h"
#include "engine/solver/neighbours.h"

namespace phyxel {

struct InclusionRemoval {
  std::string name;
  double mass = 0;             // kg, the inclusion's
  double removed = 0;          // kg of it in freed pieces
  double healthy_removed = 0;  // kg of other tissue in the freed pieces that carry it
  bool whole = false;          // all of it removed, in one piece
};

struct Resection {
  uint32_t pieces = 0;    // connected pieces (of joined pairs) with no fixed phyxel
  double freed_mass = 0;  // kg in them
  std::vector<InclusionRemoval> inclusions;  // every inclusion of the scene, in order
};

// Pieces: phyxels joined by live pairs (alive, aligned with neighbours.index), removed
// phyxels left out. A piece with a fixed phyxel is attached; every other piece is freed.
// Scenes without fixed phyxels have no attached piece: everything counts as freed.
Resection measure_resection(const Scene& scene, const PhyxelSet& set,
                            const NeighbourLists& neighbours, const std::vector<uint8_t>& alive);

}  // namespace phyxel
