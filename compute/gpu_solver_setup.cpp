#include "compute/gpu_solver_setup.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

namespace phyxel::gpu {

using layout::vec4;

namespace {

vec4 v4(const Vec3& x, double w) {
  return {float(x.x()), float(x.y()), float(x.z()), float(w)};
}

// float(x) back in double: the hi part of the split x = hi + lo (lo = float(x - hi)). Through a
// volatile float, because GCC 12 at -O2 folds the round trip (double)(float)x to x when it
// vectorises a loop around it, which left every lo at 0.
double float_part(double x) {
  volatile float f = static_cast<float>(x);
  return f;
}

// The hash cell is a little larger than h, so that float rounding of the cell coordinates
// (relative 1e-7 of an object's extent in cells) cannot put a pair closer than h two cells
// apart.
constexpr double kCellMargin = 1.0 / 1024.0;

layout::SolverClass make_class(const Material& mat, const ObjectRange& obj, uint32_t object,
                               uint32_t material) {
  layout::SolverClass c{};
  const double kv = volume_stiffness(mat);
  const double h = obj.support_radius;
  c.elastic = {float(lame_lambda(mat) - kv), float(lame_mu(mat)), float(kv), float(mat.damping)};
  c.kernel = {float(h * h), float(315.0 / (64.0 * std::numbers::pi * h * h * h)),
              float(mat.hourglass), float(h * (1 + kCellMargin))};
  // The CPU's bound h^2 (1 - 1e-9) (engine/solver/neighbours.cpp) as hi + lo for the double test,
  // and the float test's bound (shaders/solver_nbr.glsl).
  const double bound = h * h * (1 - 1e-9);
  const double hi = float_part(bound);
  c.search = {float(hi), float(bound - hi), float(h * h * (1 - 1e-5)),
              float(mat.tear_stress.value_or(0.0))};
  c.ids = {object, material, 0, 0};
  return c;
}

}  // namespace

SolverSetup prepare_solver_setup(const PhyxelSet& set, const Vec3& gravity) {
  const size_t n = set.size();
  SolverSetup s;
  s.rest.resize(n);
  s.local.resize(n);
  s.rest_lo.resize(n);
  s.ext.resize(n);
  s.velocity.resize(n);
  s.flags.resize(n);
  std::map<std::pair<uint32_t, uint32_t>, uint32_t> class_of;
  for (uint32_t o = 0; o < set.objects.size(); ++o) {
    const ObjectRange& obj = set.objects[o];
    if (obj.count == 0) continue;
    // Positions relative to the object's centre: the float differences x0_j - x0_i of the step
    // passes then lose only about 1e-7 of the object's size, not of its distance to the origin.
    Eigen::AlignedBox3d box;
    for (uint32_t i = obj.first; i < obj.first + obj.count; ++i) box.extend(set.rest[i]);
    const Vec3 centre = box.center();
    for (uint32_t i = obj.first; i < obj.first + obj.count; ++i) {
      const auto key = std::make_pair(o, set.material[i]);
      auto it = class_of.find(key);
      if (it == class_of.end()) {
        if (s.classes.size() >= layout::kMaxSolverClasses)
          throw std::invalid_argument(
              "the GPU solver supports at most 65536 (object, material) combinations");
        it = class_of.emplace(key, uint32_t(s.classes.size())).first;
        s.classes.push_back(make_class(set.materials[set.material[i]], obj, o, set.material[i]));
      }
      const Vec3 x = set.rest[i] - centre;
      const Vec3 hi(float_part(x.x()), float_part(x.y()), float_part(x.z()));
      s.rest[i] = v4(set.rest[i], set.volume[i]);
      s.local[i] = v4(hi, 0);
      s.rest_lo[i] = v4(x - hi, 0);
      s.ext[i] = v4(set.mass[i] * gravity + set.external_force[i], set.mass[i]);
      const bool fixed = (set.flags[i] & kFixed) != 0;
      s.velocity[i] = v4(fixed ? Vec3::Zero() : set.initial_velocity[i], 0);
      s.flags[i] = (set.flags[i] & 0xffu) | (it->second << layout::kFlagClassShift);
    }
  }
  return s;
}

uint64_t lattice_pair_bound(const PhyxelSet& set) {
  uint64_t total = 0;
  for (const ObjectRange& obj : set.objects) {
    uint64_t active = 0;
    for (uint32_t i = obj.first; i < obj.first + obj.count; ++i)
      if (!(set.flags[i] & kRemoved)) ++active;
    if (active < 2 || !(obj.spacing > 0)) continue;
    const double r = obj.support_radius / obj.spacing;
    const double bound = r * r * (1 - 1e-9);
    const int reach = static_cast<int>(std::ceil(r));
    uint64_t stencil = 0;
    for (int a = -reach; a <= reach; ++a)
      for (int b = -reach; b <= reach; ++b)
        for (int c = -reach; c <= reach; ++c) {
          const double d = double(a * a + b * b + c * c);
          if (d > 0 && d < bound) ++stencil;
        }
    total += active * std::min(stencil, active - 1);
  }
  return total;
}

uint32_t hash_buckets(size_t phyxels) {
  uint64_t buckets = 64;
  while (buckets < 2 * uint64_t{phyxels}) buckets *= 2;
  if (buckets > (uint64_t{1} << 31))
    throw std::invalid_argument("too many phyxels for the GPU neighbour search (" +
                                std::to_string(phyxels) + ")");
  return static_cast<uint32_t>(buckets);
}

}  // namespace phyxel::gpu
