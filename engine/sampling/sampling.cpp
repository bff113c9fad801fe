// Phyxel sampling: every scene object becomes the points of a cubic lattice inside its shape.
//
// Lattice. Spacing s per object, corners included: a box's lattice starts at its min corner
// and has floor(extent / s + 1e-6) + 1 points per axis, so points on the faces are phyxels; a
// sphere's or ellipsoid's lattice is centred on its centre (sampling symmetric under the
// shape's mirror symmetries); a mesh's starts at its bounds' min corner. A site is a phyxel
// when it lies inside the shape or within kBoundaryTolerance * s of its surface. Phyxels are
// ordered object by object, and within an object x fastest, then y, then z.
//
// Volume. A phyxel's volume is the part of its lattice cell (the cube of side s centred on it)
// inside the shape, estimated on a 4x4x4 grid of sub-cell centres, plus the inside sub-cells
// of the cells of neighbouring sites that are not phyxels, each given to the nearest phyxel of
// the 3x3x3 block around it. The phyxels' volumes so partition the shape and add up to its
// volume (to the sub-sampling error) also for curved surfaces; with the cell alone a sphere of
// radius 20 s lost 2 % of its volume, 4 % at 10 s. A box aligned with its lattice has no such
// outside parts: its faces get exactly s^3/2, edges s^3/4, corners s^3/8, and its total is
// exact when its sides are multiples of s. The volume is the quadrature weight of the energy,
// and mass = density * volume. We do not use the kernel-sum density of the paper's eq 9
// (v = m / sum m w), which halves the density at the surface and so doubles surface volumes
// (docs/decisions.md).
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "engine/geometry/image_volume.h"
#include "engine/geometry/shape.h"
#include "engine/sampling/phyxel_set.h"
#include "engine/sampling/sampling_region.h"
#include "engine/sampling/splat_radius.h"

namespace phyxel {
namespace {

// Boundary tolerance of the inside tests, in units of the spacing: lattice points exactly on
// a face, edge or pole are inside despite rounding.
constexpr double kBoundaryTolerance = 1e-9;
// Splat radius of a surface phyxel, in units of the spacing (splat_radius.h says why 0.8).
constexpr double kSplatRadius = kSplatRadiusSpacings;
// Largest lattice (sites over an object's bounds) we agree to scan: one byte per site.
constexpr double kMaxSites = 2147483648.0;  // 2^31

// The six face neighbours, in the order -x, +x, -y, +y, -z, +z.
constexpr std::array<std::array<int, 3>, 6> kFaceNeighbours = {
    {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}}};

class Errors {
 public:
  explicit Errors(const Scene& scene)
      : file_(scene.file.empty() ? std::string("<scene>") : scene.file.string()) {}
  [[noreturn]] void fail(const std::string& path, const std::string& problem) const {
    throw SceneError(file_ + ": " + path + ": " + problem);
  }

 private:
  std::string file_;
};

std::string object_path(size_t index) {
  return "objects[" + std::to_string(index) + "]";
}

std::string length(double metres) {
  char text[32];
  std::snprintf(text, sizeof text, "%g m", metres);
  return text;
}

Lattice make_lattice(const ObjectDesc& object, const std::string& path, const Errors& errors) {
  const Shape& shape = object.shape;
  Lattice lattice;
  lattice.s = object.spacing;
  const bool centred = shape.type == Shape::Type::Sphere || shape.type == Shape::Type::Ellipsoid;
  const Eigen::AlignedBox3d bounds = shape_bounds(shape);
  const Vec3 radii = shape.type == Shape::Type::Sphere ? Vec3::Constant(shape.radius) : shape.radii;
  lattice.origin = centred ? shape.center : bounds.min();
  std::array<double, 3> count{};
  for (int d = 0; d < 3; ++d) {
    const double cells = (centred ? radii[d] : bounds.max()[d] - bounds.min()[d]) / lattice.s;
    // Rounding must not drop the last layer of a side that is a multiple of s.
    const double m = std::floor(cells + 1e-6);
    count[d] = !(m >= 0) ? 0 : (centred ? 2 * m + 1 : m + 1);
  }
  const double sites = count[0] * count[1] * count[2];
  if (!(sites <= kMaxSites)) {
    char text[64];
    std::snprintf(text, sizeof text, "%.3g", sites);
    errors.fail(path + ".spacing", "the lattice over the object's bounds would have " +
                                       std::string(text) +
                                       " sites (at most 2^31); use a larger "
                                       "spacing or a smaller shape");
  }
  for (int d = 0; d < 3; ++d) {
    lattice.n[d] = static_cast<int64_t>(count[d]);
    lattice.first[d] = centred ? -(lattice.n[d] - 1) / 2 : 0;
  }
  return lattice;
}

// Direction of the missing face neighbours; when they cancel (a layer one site thick), the
// first missing one in the order of kFaceNeighbours. Zero when none is missing.
Vec3 lattice_normal(unsigned missing) {
  Vec3 sum = Vec3::Zero();
  for (int f = 0; f < 6; ++f)
    if (missing & (1u << f))
      sum += Vec3(kFaceNeighbours[f][0], kFaceNeighbours[f][1], kFaceNeighbours[f][2]);
  if (sum.squaredNorm() > 0) return sum.normalized();
  for (int f = 0; f < 6; ++f)
    if (missing & (1u << f))
      return Vec3(kFaceNeighbours[f][0], kFaceNeighbours[f][1], kFaceNeighbours[f][2]);
  return Vec3::Zero();
}

// Outward unit normal of a surface phyxel. Sphere and ellipsoid: the gradient of the implicit
// function. Box: the sum of the normals of the faces next to the point, which are exactly the
// directions of its missing neighbours (an edge gets the diagonal). Mesh: the pseudo-normal of
// the closest surface point (mesh_query.h), which matches the box on a lattice-aligned cube.
// Image: minus the gradient of the label mask blurred over 2 spacings (at least 3 voxels), so
// smooth across voxel steps also for phyxels up to a spacing below the surface (image_volume.h).
Vec3 surface_normal(const Shape& shape, const Region& region, const Vec3& p, double s,
                    unsigned missing) {
  Vec3 n = Vec3::Zero();
  switch (shape.type) {
    case Shape::Type::Sphere:
      n = p - shape.center;
      break;
    case Shape::Type::Ellipsoid:
      n = (p - shape.center).cwiseQuotient(shape.radii.cwiseProduct(shape.radii));
      break;
    case Shape::Type::Mesh:
      if (region.mesh()) n = region.mesh()->surface_normal(p, 1e-6 * s);
      break;
    case Shape::Type::Image:
      if (shape.image) n = shape.image->normal(p, std::max(2 * s, 3 * shape.image->voxel_size()));
      break;
    case Shape::Type::Box:
      break;
  }
  const double norm = n.norm();
  return norm > 0 ? Vec3(n / norm) : lattice_normal(missing);
}

// An object's lattice with its phyxel sites: inside[] per site, and the phyxels' site
// indices in lattice order (sorted), phyxel n of the object being at site linear[n].
struct Occupancy {
  Lattice lattice;
  std::vector<uint8_t> inside;
  std::vector<size_t> linear;

  bool is_phyxel(int64_t i, int64_t j, int64_t k) const {
    return lattice.valid(i, j, k) && inside[lattice.index(i, j, k)];
  }
  std::array<int64_t, 3> coords(size_t site) const {
    const auto l = static_cast<int64_t>(site);
    return {l % lattice.n[0], (l / lattice.n[0]) % lattice.n[1], l / (lattice.n[0] * lattice.n[1])};
  }
};

// Rest position, flags, normal, splat radius and own-cell volume of the object's phyxels.
void fill_phyxels(const Occupancy& occ, const Region& shape, double eps, size_t first,
                  PhyxelSet& out) {
  const double s = occ.lattice.s, cell = s * s * s;
  const auto count = static_cast<int64_t>(occ.linear.size());
#pragma omp parallel for schedule(dynamic, 256)
  for (int64_t n = 0; n < count; ++n) {
    const auto [i, j, k] = occ.coords(occ.linear[n]);
    const size_t p = first + size_t(n);
    const Vec3 x = occ.lattice.point(i, j, k);
    out.rest[p] = x;
    unsigned missing = 0;
    for (int f = 0; f < 6; ++f)
      if (!occ.is_phyxel(i + kFaceNeighbours[f][0], j + kFaceNeighbours[f][1],
                         k + kFaceNeighbours[f][2]))
        missing |= 1u << f;
    // Analytic shapes are convex: a cell whose 26 neighbours are all inside lies in their hull
    // and is full. Meshes need not be convex; their sub-cell test is cheap away from the
    // surface, so every cell takes it. Images are taken as full there too: a hole smaller than
    // the spacing between 27 inside sites is below the sampling's resolution.
    bool full = !shape.mesh() && missing == 0;
    for (int dk = -1; dk <= 1 && full; ++dk)
      for (int dj = -1; dj <= 1 && full; ++dj)
        for (int di = -1; di <= 1 && full; ++di) full = occ.is_phyxel(i + di, j + dj, k + dk);
    const int hits =
        full ? kSubcells * kSubcells * kSubcells : std::popcount(shape.subcells(x, s, true, eps));
    out.volume[p] = cell * hits / (kSubcells * kSubcells * kSubcells);
    if (missing != 0) {
      out.flags[p] |= kSurface;
      out.normal[p] = surface_normal(shape.shape(), shape, x, s, missing);
      out.splat_radius[p] = kSplatRadius * s;
    }
  }
}

// Gives the inside sub-cells of the cells of non-phyxel sites next to the object to the
// nearest phyxel of the 3x3x3 block around each (ties: the first in dk, dj, di order).
void add_outside_parts(const Occupancy& occ, const Region& shape, double eps, size_t first,
                       PhyxelSet& out) {
  const Lattice& lattice = occ.lattice;
  std::vector<size_t> border;  // non-phyxel sites with a phyxel among their 26 neighbours
  for (size_t site = 0; site < lattice.sites(); ++site) {
    if (occ.inside[site]) continue;
    const auto [i, j, k] = occ.coords(site);
    bool next_to_phyxel = false;
    for (int dk = -1; dk <= 1 && !next_to_phyxel; ++dk)
      for (int dj = -1; dj <= 1 && !next_to_phyxel; ++dj)
        for (int di = -1; di <= 1 && !next_to_phyxel; ++di)
          next_to_phyxel = occ.is_phyxel(i + di, j + dj, k + dk);
    if (next_to_phyxel) border.push_back(site);
  }
  std::vector<uint64_t> masks(border.size());
  const auto count = static_cast<int64_t>(border.size());
#pragma omp parallel for schedule(dynamic, 64)
  for (int64_t b = 0; b < count; ++b) {
    const auto [i, j, k] = occ.coords(border[b]);
    masks[b] = shape.subcells(lattice.point(i, j, k), lattice.s, false, eps);
  }
  // For each sub-cell, the 26 neighbour offsets from nearest to farthest.
  constexpr int kBits = kSubcells * kSubcells * kSubcells;
  std::vector<std::array<std::array<int, 3>, 26>> nearest(kBits);
  for (int bit = 0; bit < kBits; ++bit) {
    std::vector<std::pair<double, std::array<int, 3>>> order;
    for (int dk = -1; dk <= 1; ++dk)
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di)
          if (di || dj || dk)
            order.push_back({(subcell_offset(bit) - Vec3(di, dj, dk)).squaredNorm(), {di, dj, dk}});
    std::stable_sort(order.begin(), order.end(),
                     [](const auto& x, const auto& y) { return x.first < y.first; });
    for (int m = 0; m < 26; ++m) nearest[bit][m] = order[m].second;
  }
  // Serial, in lattice order: the sums do not depend on the number of threads.
  const double part = lattice.s * lattice.s * lattice.s / kBits;
  for (size_t b = 0; b < border.size(); ++b) {
    const auto [i, j, k] = occ.coords(border[b]);
    for (uint64_t mask = masks[b]; mask != 0; mask &= mask - 1) {
      const int bit = std::countr_zero(mask);
      for (const auto& [di, dj, dk] : nearest[bit]) {
        if (!occ.is_phyxel(i + di, j + dj, k + dk)) continue;
        const size_t site = lattice.index(i + di, j + dj, k + dk);
        const auto it = std::lower_bound(occ.linear.begin(), occ.linear.end(), site);
        out.volume[first + size_t(it - occ.linear.begin())] += part;
        break;
      }
    }
  }
}

// "box 0.1 mm across", "box 100 x 100 x 0.1 mm", "sphere of radius 1 mm", ...
std::string describe_size(const Shape& shape) {
  const auto mm = [](double metres) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", metres * 1e3);
    return std::string(text);
  };
  const Vec3 size = shape_bounds(shape).sizes();
  switch (shape.type) {
    case Shape::Type::Sphere:
      return "sphere of radius " + mm(shape.radius) + " mm";
    case Shape::Type::Ellipsoid:
      return "ellipsoid of radii " + mm(shape.radii.x()) + " x " + mm(shape.radii.y()) + " x " +
             mm(shape.radii.z()) + " mm";
    case Shape::Type::Box:
      if (size.x() == size.y() && size.y() == size.z()) return "box " + mm(size.x()) + " mm across";
      return "box " + mm(size.x()) + " x " + mm(size.y()) + " x " + mm(size.z()) + " mm";
    case Shape::Type::Image:
      return "image of bounds " + mm(size.x()) + " x " + mm(size.y()) + " x " + mm(size.z()) +
             " mm";
    case Shape::Type::Mesh:
      break;
  }
  return "mesh of bounds " + mm(size.x()) + " x " + mm(size.y()) + " x " + mm(size.z()) + " mm";
}

// The spacing at which the shape samples to a usable MLS fit: a box's lattice then has at least
// 2 sites along every side (8 phyxels, each with 6 or more neighbours); a sphere's or an
// ellipsoid's has its centre and the 6 sites around it. A mesh has no such rule: half its
// thinnest bound is a guess, so the message says "about".
double spacing_needed(const Shape& shape, double s) {
  double needed = shape_bounds(shape).sizes().minCoeff() / 2;
  if (shape.type == Shape::Type::Box) needed = 2 * needed;
  if (shape.type == Shape::Type::Sphere) needed = shape.radius;
  if (shape.type == Shape::Type::Ellipsoid) needed = shape.radii.minCoeff();
  return needed < s ? needed : s / 2;
}

// Lattice offsets k with |k| s < h (the kernel's support), nearest first.
std::vector<std::array<int, 3>> support_stencil(double s, double h) {
  std::vector<std::array<int, 3>> stencil;
  const int reach = static_cast<int>(std::ceil(h / s));
  for (int k = -reach; k <= reach; ++k)
    for (int j = -reach; j <= reach; ++j)
      for (int i = -reach; i <= reach; ++i)
        if ((i || j || k) && std::sqrt(double(i * i + j * j + k * k)) * s < h)
          stencil.push_back({i, j, k});
  std::stable_sort(stencil.begin(), stencil.end(), [](const auto& a, const auto& b) {
    return a[0] * a[0] + a[1] * a[1] + a[2] * a[2] < b[0] * b[0] + b[1] * b[1] + b[2] * b[2];
  });
  return stencil;
}

// Neighbours of phyxel n within the stencil and whether they span space (stops once both hold).
std::pair<int, bool> mls_fit(const Occupancy& occ, const std::vector<std::array<int, 3>>& stencil,
                             size_t n) {
  const auto [i, j, k] = occ.coords(occ.linear[n]);
  Eigen::Matrix3d moment = Eigen::Matrix3d::Zero();  // sum of k k^T: whole numbers
  int count = 0;
  for (const auto& [di, dj, dk] : stencil) {
    if (!occ.is_phyxel(i + di, j + dj, k + dk)) continue;
    const Vec3 d(di, dj, dk);
    moment += d * d.transpose();
    if (++count >= kMinMlsNeighbours && moment.determinant() > 0.5) return {count, true};
  }
  return {count, moment.determinant() > 0.5};
}

// Largest share of an image's phyxels that may be left out for want of a usable fit.
constexpr double kMaxImagePruned = 0.01;

// A segmentation has speckles and strands thinner than the spacing: an image shape leaves out
// the phyxels without a usable MLS fit (again, as leaving some out can strand others), as long
// as they are at most kMaxImagePruned of its phyxels; more is left to check_mls_fit to refuse.
// Returns true when every phyxel left has a usable fit (check_mls_fit would pass).
bool prune_unfit(Occupancy& occ, double h) {
  const auto stencil = support_stencil(occ.lattice.s, h);
  const size_t budget = size_t(kMaxImagePruned * double(occ.linear.size()));
  size_t pruned = 0;
  for (int pass = 0; pass < 8; ++pass) {
    std::vector<uint8_t> bad(occ.linear.size());
    const auto count = static_cast<int64_t>(occ.linear.size());
#pragma omp parallel for schedule(dynamic, 1024)
    for (int64_t n = 0; n < count; ++n) bad[n] = !mls_fit(occ, stencil, size_t(n)).second;
    const size_t found = size_t(std::count(bad.begin(), bad.end(), 1));
    if (found == 0) return occ.linear.size() >= size_t(kMinMlsNeighbours + 1);
    if (pruned + found > budget) return false;
    pruned += found;
    std::vector<size_t> kept;
    kept.reserve(occ.linear.size() - found);
    for (size_t n = 0; n < occ.linear.size(); ++n) {
      if (bad[n])
        occ.inside[occ.linear[n]] = 0;
      else
        kept.push_back(occ.linear[n]);
    }
    occ.linear = std::move(kept);
  }
  return false;
}

// Refuses an object whose MLS fit is unusable: every phyxel needs kMinMlsNeighbours neighbours
// of its object within the support radius h (|offset| < h, the kernel's support), not all in
// one plane, so that its moment matrix is invertible with room to spare; hence an object needs
// at least kMinMlsNeighbours + 1 phyxels. A body thinner than the spacing along some axis is
// one plane of phyxels: the regularised inverse keeps it finite, but it has no stiffness
// across, and a lone phyxel has no fit at all (the run turned non-finite at once).
void check_mls_fit(const Occupancy& occ, const ObjectDesc& object, double h,
                   const std::string& path, const Errors& errors) {
  const Lattice& lattice = occ.lattice;
  const double s = lattice.s;
  const auto stencil = support_stencil(s, h);
  const auto fit = [&](size_t n) { return mls_fit(occ, stencil, n); };
  const auto count = static_cast<int64_t>(occ.linear.size());
  int64_t first_bad = count;
  if (count >= kMinMlsNeighbours + 1) {
#pragma omp parallel for schedule(dynamic, 1024) reduction(min : first_bad)
    for (int64_t n = 0; n < count; ++n)
      if (!fit(size_t(n)).second) first_bad = std::min(first_bad, n);
    if (first_bad == count) return;
  }
  const std::string needed = length(spacing_needed(object.shape, s));
  const std::string rule = std::to_string(kMinMlsNeighbours) +
                           " neighbours within the support radius (" + length(h) +
                           ") not all in one plane";
  const std::string what = path + " \"" + object.name + "\" (" + describe_size(object.shape) + ")";
  const std::string samples = "samples to " + std::to_string(count) +
                              (count == 1 ? " phyxel" : " phyxels") + " with spacing " + length(s);
  const std::string fix =
      ": use a spacing of at most " +
      std::string(object.shape.type == Shape::Type::Mesh || object.shape.type == Shape::Type::Image
                      ? "about "
                      : "") +
      needed + " (" + path + ".spacing)";
  if (first_bad == count)
    errors.fail(what, samples + "; it needs at least " + std::to_string(kMinMlsNeighbours + 1) +
                          " phyxels, each with " + rule +
                          ", for its MLS moment matrix to be invertible" + fix);
  const auto [neighbours, spans] = fit(size_t(first_bad));
  const auto [i, j, k] = occ.coords(occ.linear[first_bad]);
  const Vec3 x = lattice.point(i, j, k);
  char at[96];
  std::snprintf(at, sizeof at, "(%g, %g, %g) m", x.x(), x.y(), x.z());
  errors.fail(what, samples + ", but the phyxel at " + at + " has " + std::to_string(neighbours) +
                        (neighbours == 1 ? " neighbour" : " neighbours") +
                        (spans || neighbours < 3 ? "" : ", all in one plane") +
                        " (the object is about one phyxel thin there, so it has no stiffness "
                        "across); every phyxel needs " +
                        rule + " for its MLS moment matrix to be invertible" + fix);
}

// Scenes built in code may skip load_mesh; the scene reader always loads meshes and images.
void check_loaded_shapes(const ObjectDesc& object, const std::string& path, const Errors& errors) {
  auto check_mesh = [&](const Shape& shape, const std::string& at) {
    if (shape.type == Shape::Type::Mesh && !shape.mesh)
      errors.fail(at,
                  "the mesh shape has no loaded surface; read the scene with load_scene() "
                  "or fill Shape::mesh with load_mesh()");
    if (shape.type == Shape::Type::Image && !shape.image)
      errors.fail(at,
                  "the image shape has no loaded label mask; read the scene with load_scene() "
                  "or fill Shape::image with a LabelMask");
  };
  check_mesh(object.shape, path + ".shape");
  for (size_t c = 0; c < object.inclusions.size(); ++c)
    check_mesh(object.inclusions[c].shape, path + ".inclusions[" + std::to_string(c) + "].shape");
  for (size_t f = 0; f < object.fixed.size(); ++f)
    check_mesh(object.fixed[f], path + ".fixed[" + std::to_string(f) + "]");
  for (size_t l = 0; l < object.loads.size(); ++l)
    check_mesh(object.loads[l].region, path + ".loads[" + std::to_string(l) + "].region");
}

// Inclusions in order, so that a later one wins where they overlap: the material of the
// object's phyxels (from `first` on) inside each.
void assign_inclusions(const ObjectDesc& object, const std::string& path, const Errors& errors,
                       uint32_t inclusion_base, size_t first, double eps, PhyxelSet& out) {
  const double s = object.spacing;
  const auto count = static_cast<int64_t>(out.size() - first);
  for (size_t c = 0; c < object.inclusions.size(); ++c) {
    const Region region(object.inclusions[c].shape);
    const auto material = static_cast<uint32_t>(inclusion_base + c);
    int64_t hits = 0;
#pragma omp parallel for schedule(dynamic, 256) reduction(+ : hits)
    for (int64_t n = 0; n < count; ++n) {
      if (region.contains(out.rest[first + n], eps)) {
        out.material[first + n] = material;
        ++hits;
      }
    }
    if (hits == 0)
      errors.fail(path + ".inclusions[" + std::to_string(c) + "].shape",
                  "the inclusion contains no phyxel of the object, so its material would be "
                  "unused; move or enlarge it so that it covers some of the object's lattice "
                  "points (spacing " +
                      length(s) + ")");
  }
}

// The object's phyxels (from `first` on) in its fixed regions.
void mark_fixed(const ObjectDesc& object, const std::string& path, const Errors& errors,
                size_t first, double eps, PhyxelSet& out) {
  const double s = object.spacing;
  const auto count = static_cast<int64_t>(out.size() - first);
  for (size_t f = 0; f < object.fixed.size(); ++f) {
    const Region region(object.fixed[f]);
    int64_t hits = 0;
#pragma omp parallel for schedule(dynamic, 256) reduction(+ : hits)
    for (int64_t n = 0; n < count; ++n) {
      if (region.contains(out.rest[first + n], eps)) {
        out.flags[first + n] |= kFixed;
        ++hits;
      }
    }
    if (hits == 0)
      errors.fail(path + ".fixed[" + std::to_string(f) + "]",
                  "the region contains no phyxel of the object; move or enlarge it so that it "
                  "covers some of the object's lattice points (spacing " +
                      length(s) + ")");
  }
}

// Each load's force is spread over the phyxels in its region in proportion to their volume,
// so that the forces add up to the load.
void spread_loads(const ObjectDesc& object, const std::string& path, const Errors& errors,
                  size_t first, double eps, PhyxelSet& out) {
  const double s = object.spacing;
  const auto count = static_cast<int64_t>(out.size() - first);
  std::vector<uint8_t> in_region(count);
  for (size_t l = 0; l < object.loads.size(); ++l) {
    const Region region(object.loads[l].region);
#pragma omp parallel for schedule(dynamic, 256)
    for (int64_t n = 0; n < count; ++n) in_region[n] = region.contains(out.rest[first + n], eps);
    double volume = 0;
    for (int64_t n = 0; n < count; ++n)
      if (in_region[n]) volume += out.volume[first + n];
    if (!(volume > 0))
      errors.fail(path + ".loads[" + std::to_string(l) + "].region",
                  "the region contains no phyxel of the object, so its force would act on "
                  "nothing; move or enlarge it so that it covers some of the object's lattice "
                  "points (spacing " +
                      length(s) + ")");
    const Load& load = object.loads[l];
    LoadSpread spread;
    spread.object = static_cast<uint32_t>(out.objects.size());
    spread.from = load.from;
    spread.until = load.until;
    for (int64_t n = 0; n < count; ++n) {
      if (!in_region[n]) continue;
      spread.phyxels.push_back(static_cast<uint32_t>(first + n));
      spread.forces.push_back(load.force * (out.volume[first + n] / volume));
    }
    if (spread.active_at(0))
      for (size_t k = 0; k < spread.phyxels.size(); ++k)
        out.external_force[spread.phyxels[k]] += spread.forces[k];
    out.loads.push_back(std::move(spread));
  }
}

void sample_object(const Scene& scene, size_t oi, uint32_t inclusion_base,
                   const SamplingOptions& options, PhyxelSet& out) {
  const ObjectDesc& object = scene.objects[oi];
  const Errors errors(scene);
  const std::string path = object_path(oi);
  const double s = object.spacing;
  if (!(std::isfinite(s) && s > 0))
    errors.fail(path + ".spacing", "the spacing must be a positive length in metres");
  const double eps = kBoundaryTolerance * s;
  check_loaded_shapes(object, path, errors);
  const Region shape(object.shape);
  Occupancy occ;
  occ.lattice = make_lattice(object, path, errors);
  occ.inside.assign(occ.lattice.sites(), 0);
  shape.classify(occ.lattice, eps, &occ.inside);
  for (size_t site = 0; site < occ.inside.size(); ++site)
    if (occ.inside[site]) occ.linear.push_back(site);
  if (occ.linear.empty())
    errors.fail(path + ".shape",
                "no lattice point of spacing " + length(s) +
                    " lies inside the shape; make the shape larger than the spacing or lower " +
                    path + ".spacing");
  const double h = object.support_radius > 0 ? object.support_radius : 2 * s;
  // An image's pruning scans every phyxel's fit; when all are usable the check need not rescan.
  const bool all_fit =
      options.require_usable_fit && object.shape.type == Shape::Type::Image && prune_unfit(occ, h);
  if (options.require_usable_fit && !all_fit) check_mls_fit(occ, object, h, path, errors);
  const size_t first = out.size();
  if (first + occ.linear.size() > UINT32_MAX)
    errors.fail(path + ".spacing",
                "the scene would have more than 2^32 phyxels; use a larger spacing");
  const size_t total = first + occ.linear.size();
  const auto count = static_cast<int64_t>(occ.linear.size());

  out.rest.resize(total);
  out.volume.resize(total);
  out.mass.resize(total);
  out.material.resize(total, static_cast<uint32_t>(oi));
  out.object.resize(total, static_cast<uint32_t>(oi));
  out.flags.resize(total, 0);
  out.normal.resize(total, Vec3::Zero());
  out.splat_radius.resize(total, 0);
  out.external_force.resize(total, Vec3::Zero());
  out.initial_velocity.resize(total, object.initial_velocity);
  fill_phyxels(occ, shape, eps, first, out);
  add_outside_parts(occ, shape, eps, first, out);
  // A site inside by its own point with none of its sub-cell centres inside (a sliver of a
  // segmentation) gets one sub-cell's volume, not none: a massless phyxel cannot move.
  for (size_t p = first; p < total; ++p)
    if (!(out.volume[p] > 0)) out.volume[p] = s * s * s / (kSubcells * kSubcells * kSubcells);

  assign_inclusions(object, path, errors, inclusion_base, first, eps, out);
  for (size_t p = first; p < total; ++p)
    out.mass[p] = out.materials[out.material[p]].density * out.volume[p];

  mark_fixed(object, path, errors, first, eps, out);

  spread_loads(object, path, errors, first, eps, out);

  ObjectRange range;
  range.name = object.name;
  range.first = static_cast<uint32_t>(first);
  range.count = static_cast<uint32_t>(count);
  range.spacing = s;
  range.support_radius = h;
  range.cut_band = object.cut_band;
  out.objects.push_back(range);
}

}  // namespace

PhyxelSet sample_scene(const Scene& scene, const SamplingOptions& options) {
  PhyxelSet out;
  // materials: [0, objects) holds object k's material at index k; then come the inclusions,
  // object by object and in their order within an object, so inclusion c of object k is at
  // objects.size() + (inclusions of objects 0..k-1) + c.
  std::vector<uint32_t> inclusion_base(scene.objects.size());
  for (const ObjectDesc& object : scene.objects) out.materials.push_back(object.material);
  for (size_t k = 0; k < scene.objects.size(); ++k) {
    inclusion_base[k] = static_cast<uint32_t>(out.materials.size());
    for (const Inclusion& inclusion : scene.objects[k].inclusions)
      out.materials.push_back(inclusion.material);
  }
  for (size_t k = 0; k < scene.objects.size(); ++k)
    sample_object(scene, k, inclusion_base[k], options, out);
  return out;
}

std::vector<Vec3> external_forces_at(const PhyxelSet& set, double t) {
  std::vector<Vec3> f(set.size(), Vec3::Zero());
  for (const LoadSpread& load : set.loads)
    if (load.active_at(t))
      for (size_t k = 0; k < load.phyxels.size(); ++k) f[load.phyxels[k]] += load.forces[k];
  return f;
}

}  // namespace phyxel
