#include "engine/surgery/resection.h"

#include <numeric>

namespace phyxel {
namespace {

// Union-find over phyxels with path halving.
struct Pieces {
  std::vector<uint32_t> parent;
  explicit Pieces(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  uint32_t find(uint32_t x) {
    while (parent[x] != x) {
      parent[x] = parent[parent[x]];
      x = parent[x];
    }
    return x;
  }
  void join(uint32_t a, uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

}  // namespace

Resection measure_resection(const Scene& scene, const PhyxelSet& set,
                            const NeighbourLists& neighbours, const std::vector<uint8_t>& alive) {
  const size_t n = set.size();
  Pieces pieces(n);
  for (uint32_t i = 0; i < n; ++i)
    for (uint32_t k = neighbours.offset[i]; k < neighbours.offset[i + 1]; ++k)
      if (alive[k] && !(set.flags[i] & kRemoved) && !(set.flags[neighbours.index[k]] & kRemoved))
        pieces.join(i, neighbours.index[k]);
  std::vector<uint8_t> attached(n, 0);
  for (uint32_t i = 0; i < n; ++i)
    if (set.flags[i] & kFixed) attached[pieces.find(i)] = 1;

  Resection r;
  std::vector<uint8_t> counted(n, 0);
  for (uint32_t i = 0; i < n; ++i) {
    if (set.flags[i] & kRemoved) continue;
    const uint32_t root = pieces.find(i);
    if (attached[root]) continue;
    r.freed_mass += set.mass[i];
    if (!counted[root]) {
      counted[root] = 1;
      ++r.pieces;
    }
  }

  // Inclusions: material index objects.size() + running count (engine/sampling).
  uint32_t material = static_cast<uint32_t>(scene.objects.size());
  for (const ObjectDesc& object : scene.objects) {
    for (const Inclusion& inclusion : object.inclusions) {
      InclusionRemoval out;
      out.name = inclusion.name;
      std::vector<uint8_t> carries(n, 0);  // freed pieces with some of it
      uint32_t first_root = UINT32_MAX;
      bool one_piece = true;
      for (uint32_t i = 0; i < n; ++i) {
        if (set.material[i] != material || (set.flags[i] & kRemoved)) continue;
        out.mass += set.mass[i];
        const uint32_t root = pieces.find(i);
        if (attached[root]) continue;
        out.removed += set.mass[i];
        carries[root] = 1;
        if (first_root == UINT32_MAX) first_root = root;
        one_piece = one_piece && root == first_root;
      }
      for (uint32_t i = 0; i < n; ++i)
        if (set.material[i] != material && !(set.flags[i] & kRemoved) && carries[pieces.find(i)])
          out.healthy_removed += set.mass[i];
      out.whole = out.mass > 0 && out.removed == out.mass && one_piece;
      r.inclusions.push_back(out);
      ++material;
    }
  }
  return r;
}

}  // namespace phyxel
