#include "engine/sampling/phyxel_order.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

namespace phyxel {

namespace {

// The 21 low bits of v spread to every third bit.
uint64_t spread3(uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

template <class T>
void apply(std::vector<T>& v, const std::vector<uint32_t>& order) {
  if (v.size() != order.size()) return;  // an optional per-phyxel array left empty
  std::vector<T> out(v.size());
  for (size_t k = 0; k < order.size(); ++k) out[k] = v[order[k]];
  v.swap(out);
}

}  // namespace

std::vector<uint32_t> morton_order(const PhyxelSet& set) {
  std::vector<uint32_t> order(set.size());
  std::iota(order.begin(), order.end(), 0u);
  std::vector<uint64_t> key(set.size());
  for (const ObjectRange& o : set.objects) {
    if (o.count == 0) continue;
    Vec3 lo = set.rest[o.first];
    for (uint32_t i = o.first; i < o.first + o.count; ++i) lo = lo.cwiseMin(set.rest[i]);
    for (uint32_t i = o.first; i < o.first + o.count; ++i) {
      const Vec3 c = ((set.rest[i] - lo) / o.spacing).array().round();
      key[i] =
          spread3(uint64_t(c.x())) | spread3(uint64_t(c.y())) << 1 | spread3(uint64_t(c.z())) << 2;
    }
    std::stable_sort(order.begin() + o.first, order.begin() + o.first + o.count,
                     [&](uint32_t a, uint32_t b) { return key[a] < key[b]; });
  }
  return order;
}

void permute_phyxels(PhyxelSet& set, const std::vector<uint32_t>& order) {
  if (order.size() != set.size())
    throw std::invalid_argument("permute_phyxels: an order of " + std::to_string(order.size()) +
                                " for " + std::to_string(set.size()) + " phyxels");
  std::vector<uint32_t> new_of(set.size(), UINT32_MAX);
  for (uint32_t k = 0; k < order.size(); ++k) {
    if (order[k] >= set.size() || new_of[order[k]] != UINT32_MAX)
      throw std::invalid_argument("permute_phyxels: the order is not a permutation");
    new_of[order[k]] = k;
  }
  for (uint32_t k = 0; k < order.size(); ++k) {
    if (set.object[order[k]] != set.object[k])
      throw std::invalid_argument("permute_phyxels: phyxel " + std::to_string(order[k]) +
                                  " would leave its object's range");
  }
  apply(set.rest, order);
  apply(set.volume, order);
  apply(set.mass, order);
  apply(set.material, order);
  apply(set.object, order);
  apply(set.flags, order);
  apply(set.normal, order);
  apply(set.splat_radius, order);
  apply(set.external_force, order);
  apply(set.initial_velocity, order);
  for (LoadSpread& load : set.loads)
    for (uint32_t& p : load.phyxels) p = new_of[p];
}

}  // namespace phyxel
