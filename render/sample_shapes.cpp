#include "render/sample_shapes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>

namespace phyxel::render {
namespace {

constexpr double kSplatRadius = 0.8;  // in spacings, as engine/sampling/sampling.cpp

constexpr std::array<std::array<int, 3>, 6> kFaces = {
    {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}}};

// Every lattice point origin + s (i, j, k), |i|,|j|,|k| <= n, for which `inside` holds;
// surface where `outer` fails for a face neighbour.
PhyxelSet lattice(const Vec3& origin, double s, const std::array<int, 3>& lo,
                  const std::array<int, 3>& hi, const std::function<bool(const Vec3&)>& inside,
                  const std::function<bool(const Vec3&)>& outer,
                  const std::function<Vec3(const Vec3&, unsigned)>& normal) {
  PhyxelSet set;
  Material m;
  m.young = 3000;
  m.poisson = 0.45;
  m.density = 1000;
  set.materials.push_back(m);
  for (int k = lo[2]; k <= hi[2]; ++k)
    for (int j = lo[1]; j <= hi[1]; ++j)
      for (int i = lo[0]; i <= hi[0]; ++i) {
        const Vec3 x = origin + s * Vec3(i, j, k);
        if (!inside(x)) continue;
        unsigned missing = 0;
        for (int f = 0; f < 6; ++f)
          if (!outer(x + s * Vec3(kFaces[f][0], kFaces[f][1], kFaces[f][2]))) missing |= 1u << f;
        set.rest.push_back(x);
        set.volume.push_back(s * s * s);
        set.mass.push_back(m.density * s * s * s);
        set.material.push_back(0);
        set.object.push_back(0);
        set.flags.push_back(missing != 0 ? uint32_t(kSurface) : 0u);
        set.normal.push_back(missing != 0 ? normal(x, missing) : Vec3::Zero());
        set.splat_radius.push_back(missing != 0 ? kSplatRadius * s : 0.0);
        set.external_force.push_back(Vec3::Zero());
        set.initial_velocity.push_back(Vec3::Zero());
      }
  ObjectRange range;
  range.name = "shape";
  range.first = 0;
  range.count = static_cast<uint32_t>(set.rest.size());
  range.spacing = s;
  range.support_radius = 2 * s;
  set.objects.push_back(range);
  return set;
}

}  // namespace

PhyxelSet lattice_sphere(const Vec3& centre, double radius, double s, double shell) {
  const int n = static_cast<int>(std::ceil(radius / s)) + 1;
  const double r2 = radius * radius * (1 + 1e-12);
  const double inner = shell > 0 ? std::max(0.0, radius - shell) : 0.0;
  auto outer = [&](const Vec3& x) { return (x - centre).squaredNorm() <= r2; };
  auto inside = [&](const Vec3& x) {
    const double d2 = (x - centre).squaredNorm();
    return d2 <= r2 && (shell <= 0 || d2 > inner * inner);
  };
  auto normal = [&](const Vec3& x, unsigned) {
    const Vec3 d = x - centre;
    return d.norm() > 0 ? Vec3(d.normalized()) : Vec3(Vec3::UnitZ());
  };
  return lattice(centre, s, {-n, -n, -n}, {n, n, n}, inside, outer, normal);
}

PhyxelSet lattice_box(const Vec3& min, const Vec3& max, double s) {
  const Vec3 extent = max - min;
  const std::array<int, 3> hi = {static_cast<int>(std::floor(extent.x() / s + 1e-6)),
                                 static_cast<int>(std::floor(extent.y() / s + 1e-6)),
                                 static_cast<int>(std::floor(extent.z() / s + 1e-6))};
  const double tol = 1e-9 * s;
  auto inside = [&](const Vec3& x) {
    return (x.array() >= min.array() - tol).all() && (x.array() <= max.array() + tol).all();
  };
  auto normal = [](const Vec3&, unsigned missing) {
    Vec3 n = Vec3::Zero();
    for (int f = 0; f < 6; ++f)
      if (missing & (1u << f)) n += Vec3(kFaces[f][0], kFaces[f][1], kFaces[f][2]);
    return n.norm() > 0 ? Vec3(n.normalized()) : Vec3(Vec3::UnitZ());
  };
  return lattice(min, s, {0, 0, 0}, hi, inside, inside, normal);
}

}  // namespace phyxel::render
