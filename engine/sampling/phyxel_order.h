// Phyxel numbering. sample_scene numbers each object's lattice with x fastest; a solver that
// gathers neighbours (the GPU's passes) may run faster on a numbering that keeps a neighbourhood
// close in memory. morton_order gives each object's phyxels in Z-order (Morton) of their lattice
// coordinates; permute_phyxels renumbers a set (objects stay contiguous ranges, loads follow).
#pragma once

#include <cstdint>
#include <vector>

#include "engine/sampling/phyxel_set.h"

namespace phyxel {

// order[k] = the phyxel that becomes phyxel k: within each object, ascending Morton code of
// round((x0 - the object's lowest x0) / spacing) (21 bits per axis), ties by index.
std::vector<uint32_t> morton_order(const PhyxelSet& set);

// Renumbers `set` so that new phyxel k is old phyxel order[k]. `order` must be a permutation
// that keeps every object's range (std::invalid_argument otherwise).
void permute_phyxels(PhyxelSet& set, const std::vector<uint32_t>& order);

}  // namespace phyxel
