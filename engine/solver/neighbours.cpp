#include "engine/solver/neighbours.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>
#include <utility>

#include <Eigen/Geometry>

namespace phyxel {
namespace {

// Counting-sort hash grid of one object's phyxels, cell size = support radius.
struct CellGrid {
  Vec3 origin;
  double cell = 1;
  Eigen::Vector3i dims{1, 1, 1};
  std::vector<uint32_t> cell_start;  // size cells + 1
  std::vector<uint32_t> sorted;      // phyxel indices grouped by cell

  Eigen::Vector3i cell_of(const Vec3& p) const {
    Eigen::Vector3i c;
    for (int a = 0; a < 3; ++a) {
      const int k = static_cast<int>(std::floor((p[a] - origin[a]) / cell));
      c[a] = std::clamp(k, 0, dims[a] - 1);
    }
    return c;
  }
  size_t key(const Eigen::Vector3i& c) const {
    return (static_cast<size_t>(c.z()) * dims.y() + c.y()) * dims.x() + c.x();
  }
};

CellGrid build_grid(const PhyxelSet& set, const std::vector<uint32_t>& members, double h) {
  CellGrid g;
  g.cell = h;
  Eigen::AlignedBox3d box;
  for (uint32_t i : members) box.extend(set.rest[i]);
  g.origin = box.min();
  for (int a = 0; a < 3; ++a)
    g.dims[a] = std::max(1, static_cast<int>(std::floor(box.sizes()[a] / h)) + 1);
  const size_t cells = static_cast<size_t>(g.dims.x()) * g.dims.y() * g.dims.z();
  g.cell_start.assign(cells + 1, 0);
  for (uint32_t i : members) ++g.cell_start[g.key(g.cell_of(set.rest[i])) + 1];
  std::partial_sum(g.cell_start.begin(), g.cell_start.end(), g.cell_start.begin());
  g.sorted.resize(members.size());
  std::vector<uint32_t> fill(g.cell_start.begin(), g.cell_start.end() - 1);
  for (uint32_t i : members) g.sorted[fill[g.key(g.cell_of(set.rest[i]))]++] = i;
  return g;
}

// set_search_stop's check, and how often the search polls it (in phyxels: the first of each
// dynamic chunk).
std::function<bool()> search_stop;
constexpr size_t kPollEvery = kSetupPollEvery;

}  // namespace

void set_search_stop(std::function<bool()> stop) {
  search_stop = std::move(stop);
}

bool search_stop_requested() {
  return search_stop && search_stop();
}

NeighbourLists find_rest_neighbours(const PhyxelSet& set) {
  const size_t n = set.size();
  std::vector<std::vector<uint32_t>> rows(n);
  for (const ObjectRange& obj : set.objects) {
    std::vector<uint32_t> members;
    members.reserve(obj.count);
    for (uint32_t i = obj.first; i < obj.first + obj.count; ++i)
      if (!(set.flags[i] & kRemoved)) members.push_back(i);
    if (members.empty()) continue;
    const double h = obj.support_radius;
    // Points at distance h have zero weight: leave them out even when rounding puts them a
    // hair inside (a lattice at h = 2 s would otherwise gain a few zero-weight neighbours).
    const double h2 = h * h * (1 - 1e-9);
    const CellGrid g = build_grid(set, members, h);
    std::atomic<bool> stopped{false};
#pragma omp parallel for schedule(dynamic, 256)
    for (size_t m = 0; m < members.size(); ++m) {
      if (stopped.load(std::memory_order_relaxed)) continue;
      if (m % kPollEvery == 0 && search_stop && search_stop()) {
        stopped.store(true, std::memory_order_relaxed);
        continue;
      }
      const uint32_t i = members[m];
      const Eigen::Vector3i c = g.cell_of(set.rest[i]);
      std::vector<uint32_t>& row = rows[i];
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const Eigen::Vector3i d = c + Eigen::Vector3i(dx, dy, dz);
            if ((d.array() < 0).any() || (d.array() >= g.dims.array()).any()) continue;
            const size_t k = g.key(d);
            for (uint32_t s = g.cell_start[k]; s < g.cell_start[k + 1]; ++s) {
              const uint32_t j = g.sorted[s];
              if (j != i && (set.rest[j] - set.rest[i]).squaredNorm() < h2) row.push_back(j);
            }
          }
      std::sort(row.begin(), row.end());
    }
    if (stopped.load()) throw SearchStopped();
  }
  NeighbourLists out;
  out.offset.resize(n + 1, 0);
  for (size_t i = 0; i < n; ++i) out.offset[i + 1] = out.offset[i] + rows[i].size();
  out.index.reserve(out.offset[n]);
  for (const auto& row : rows) out.index.insert(out.index.end(), row.begin(), row.end());
  return out;
}

}  // namespace phyxel
