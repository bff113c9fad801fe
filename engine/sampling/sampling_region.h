// Internal to sampling.cpp: an object's lattice, and the inside tests of one scene shape
// prepared for many queries (a mesh gets its BVH).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "engine/geometry/mesh_query.h"
#include "engine/scene/scene.h"

namespace phyxel {

// Sub-cell centres per axis of the volume estimate of a cell: 4^3 = 64, one bit each.
constexpr int kSubcells = 4;

// A block of lattice sites: site (i, j, k) is at origin + s * (first + (i, j, k)).
struct Lattice {
  Vec3 origin = Vec3::Zero();
  std::array<int64_t, 3> first{};  // lattice coordinate of the first site per axis
  std::array<int64_t, 3> n{};      // sites per axis
  double s = 0;

  Vec3 point(int64_t i, int64_t j, int64_t k) const {
    return origin + s * Vec3(double(first[0] + i), double(first[1] + j), double(first[2] + k));
  }
  bool valid(int64_t i, int64_t j, int64_t k) const {
    return i >= 0 && j >= 0 && k >= 0 && i < n[0] && j < n[1] && k < n[2];
  }
  size_t index(int64_t i, int64_t j, int64_t k) const { return size_t((k * n[1] + j) * n[0] + i); }
  size_t sites() const { return size_t(n[0] * n[1] * n[2]); }
};

// Offset of sub-cell centre `bit` from its cell's centre, in units of the spacing.
inline Vec3 subcell_offset(int bit) {
  const int a = bit % kSubcells, b = (bit / kSubcells) % kSubcells,
            c = bit / (kSubcells * kSubcells);
  return (Vec3(a, b, c).array() + 0.5) / kSubcells - 0.5;
}

class Region {
 public:
  explicit Region(const Shape& shape);
  Region(const Region&) = delete;
  Region& operator=(const Region&) = delete;

  // Inside or within eps of the surface.
  bool contains(const Vec3& p, double eps) const;
  // contains() for every site of the lattice, into inside[lattice.index(...)]. Meshes classify
  // whole blocks far from the surface with one query.
  void classify(const Lattice& lattice, double eps, std::vector<uint8_t>* inside) const;
  // Which sub-cell centres of the cell of side s centred on x (a site whose own status is
  // x_inside) are inside: bit b for subcell_offset(b).
  uint64_t subcells(const Vec3& x, double s, bool x_inside, double eps) const;
  const Shape& shape() const { return shape_; }
  const MeshQuery* mesh() const { return query_ ? &*query_ : nullptr; }

 private:
  void classify_block(const Lattice& lattice, std::array<int64_t, 3> lo, std::array<int64_t, 3> hi,
                      double eps, std::vector<uint8_t>* inside) const;

  const Shape& shape_;
  std::optional<MeshQuery> query_;
};

}  // namespace phyxel
