// Inside tests of scene shapes over lattices and cells (sampling_region.h).
#include "engine/sampling/sampling_region.h"

#include "engine/geometry/shape.h"

namespace phyxel {

Region::Region(const Shape& shape) : shape_(shape) {
  if (shape.type == Shape::Type::Mesh && shape.mesh) query_.emplace(*shape.mesh);
}

bool Region::contains(const Vec3& p, double eps) const {
  return query_ ? query_->contains(p, eps) : shape_contains(shape_, p, eps);
}

void Region::classify(const Lattice& lattice, double eps, std::vector<uint8_t>* inside) const {
  if (!query_) {
    // Iterations are independent: results do not depend on the number of threads.
#pragma omp parallel for schedule(dynamic, 1)
    for (int64_t k = 0; k < lattice.n[2]; ++k)
      for (int64_t j = 0; j < lattice.n[1]; ++j)
        for (int64_t i = 0; i < lattice.n[0]; ++i)
          (*inside)[lattice.index(i, j, k)] = shape_contains(shape_, lattice.point(i, j, k), eps);
    return;
  }
  // Meshes: chunks of 16^3 sites in parallel, each refined where the surface passes.
  constexpr int64_t kChunk = 16;
  std::array<int64_t, 3> chunks;
  for (int d = 0; d < 3; ++d) chunks[d] = (lattice.n[d] + kChunk - 1) / kChunk;
  const int64_t total = chunks[0] * chunks[1] * chunks[2];
#pragma omp parallel for schedule(dynamic, 1)
  for (int64_t c = 0; c < total; ++c) {
    const std::array<int64_t, 3> at = {c % chunks[0], (c / chunks[0]) % chunks[1],
                                       c / (chunks[0] * chunks[1])};
    std::array<int64_t, 3> lo, hi;
    for (int d = 0; d < 3; ++d) {
      lo[d] = at[d] * kChunk;
      hi[d] = std::min(lo[d] + kChunk, lattice.n[d]);
    }
    classify_block(lattice, lo, hi, eps, inside);
  }
}

// A block of sites [lo, hi) with no surface within its circumscribed ball lies on one side of
// the surface: one winding number at its centre classifies it. Otherwise it is split in
// halves along every axis, down to single sites near the surface, which the closest-point
// test classifies.
void Region::classify_block(const Lattice& lattice, std::array<int64_t, 3> lo,
                            std::array<int64_t, 3> hi, double eps,
                            std::vector<uint8_t>* inside) const {
  if (hi[0] - lo[0] == 1 && hi[1] - lo[1] == 1 && hi[2] - lo[2] == 1) {
    (*inside)[lattice.index(lo[0], lo[1], lo[2])] =
        query_->contains_near(lattice.point(lo[0], lo[1], lo[2]), eps);
    return;
  }
  const Vec3 a = lattice.point(lo[0], lo[1], lo[2]);
  const Vec3 b = lattice.point(hi[0] - 1, hi[1] - 1, hi[2] - 1);
  const Vec3 center = (a + b) / 2;
  const double radius = (b - a).norm() / 2;
  if (!query_->surface_within(center, radius + eps)) {
    const uint8_t status = query_->winding_number(center) > 0.5;
    for (int64_t k = lo[2]; k < hi[2]; ++k)
      for (int64_t j = lo[1]; j < hi[1]; ++j)
        for (int64_t i = lo[0]; i < hi[0]; ++i) (*inside)[lattice.index(i, j, k)] = status;
    return;
  }
  std::array<std::array<int64_t, 3>, 3> cuts;  // per axis: lo, middle, hi
  for (int d = 0; d < 3; ++d) cuts[d] = {lo[d], lo[d] + (hi[d] - lo[d] + 1) / 2, hi[d]};
  for (int c = 0; c < 2; ++c)
    for (int b2 = 0; b2 < 2; ++b2)
      for (int a2 = 0; a2 < 2; ++a2) {
        const std::array<int64_t, 3> l = {cuts[0][a2], cuts[1][b2], cuts[2][c]};
        const std::array<int64_t, 3> h = {cuts[0][a2 + 1], cuts[1][b2 + 1], cuts[2][c + 1]};
        if (l[0] < h[0] && l[1] < h[1] && l[2] < h[2]) classify_block(lattice, l, h, eps, inside);
      }
}

uint64_t Region::subcells(const Vec3& x, double s, bool x_inside, double eps) const {
  static_assert(kSubcells == 4, "MeshQuery::inside_subcells samples 4x4x4 sub-cells");
  if (query_) return query_->inside_subcells(x, s, x_inside, eps);
  uint64_t mask = 0;
  for (int bit = 0; bit < kSubcells * kSubcells * kSubcells; ++bit)
    if (shape_contains(shape_, x + s * subcell_offset(bit), eps)) mask |= uint64_t(1) << bit;
  return mask;
}

}  // namespace phyxel
