// Rest-state neighbour lists (total Lagrangian): found once by spatial hashing, symmetric,
// sorted by index, within one object only. Compressed rows: the neighbours of phyxel i are
// index[offset[i] .. offset[i+1]).
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/sampling/phyxel_set.h"

namespace phyxel {

struct NeighbourLists {
  std::vector<uint32_t> offset;  // size N + 1
  std::vector<uint32_t> index;   // size offset[N]

  uint32_t count(size_t i) const { return offset[i + 1] - offset[i]; }
  // The position of j in the row of i (the rows are sorted), or kNoSlot when j is not a
  // neighbour of i.
  static constexpr size_t kNoSlot = ~size_t{0};
  size_t slot(uint32_t i, uint32_t j) const {
    const auto row = index.begin() + offset[i];
    const auto end = index.begin() + offset[i + 1];
    const auto at = std::lower_bound(row, end, j);
    return at != end && *at == j ? size_t(at - index.begin()) : kNoSlot;
  }
};

// Pairs (i, j), i != j, of the same object with |x0_j - x0_i|^2 < h^2 (1 - 1e-9), h the
// object's support radius.
// Phyxels flagged kRemoved get no neighbours and are no one's neighbour.
// Polled every few thousand phyxels, `search_stop` (set_search_stop; none by default) may end
// it: it then throws SearchStopped. The command line's Ctrl-C handler sets it, so a search
// that takes seconds stops within a fraction of one.
NeighbourLists find_rest_neighbours(const PhyxelSet& set);

// The same stop ends the solvers' MLS precompute (polled every 256 phyxels; `phase` names it).
class SearchStopped : public std::runtime_error {
 public:
  explicit SearchStopped(const std::string& phase = "the neighbour search")
      : std::runtime_error("stopped during " + phase) {}
};
// Process-wide; called from the search's threads at once (read atomics only). Empty: never.
void set_search_stop(std::function<bool()> stop);
// The stop's answer now (false without one): for the setup passes after the search.
bool search_stop_requested();
// Phyxels between two polls of the stop, in the search and the precompute.
inline constexpr size_t kSetupPollEvery = 256;

}  // namespace phyxel
