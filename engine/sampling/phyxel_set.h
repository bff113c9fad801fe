// PhyxelSet: the sampled points of all objects, structure of arrays, in double precision.
// Produced by sample_scene() (sampling.cpp); read by the solvers and the output writers.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "engine/scene/scene.h"

namespace phyxel {

enum PhyxelFlags : uint32_t {
  kFixed = 1u << 0,    // never moves (inside a `fixed` region)
  kSurface = 1u << 1,  // on the object's boundary: has a normal and a splat radius
  kRemoved = 1u << 2,  // deactivated (cut away); takes no part in the physics
};

// One object's slice of the arrays: phyxels [first, first + count).
struct ObjectRange {
  std::string name;
  uint32_t first = 0;
  uint32_t count = 0;
  double spacing = 0;
  double support_radius = 0;
  double cut_band = 0;  // spacings (ObjectDesc::cut_band); 0: no band
};

// One scene load spread over its phyxels (volume-weighted), with its time window.
struct LoadSpread {
  uint32_t object = 0;
  double from = 0, until = 0;  // active during [from, until) of simulated time
  std::vector<uint32_t> phyxels;
  std::vector<Vec3> forces;  // N, adding up to the load's force
  bool active_at(double t) const { return from <= t && t < until; }
};

struct PhyxelSet {
  std::vector<Vec3> rest;            // x0, m
  std::vector<double> volume;        // quadrature volume: the part of its lattice cell inside
  std::vector<double> mass;          // kg, density * volume
  std::vector<uint32_t> material;    // index into `materials`
  std::vector<uint32_t> object;      // index into `objects`
  std::vector<uint32_t> flags;       // PhyxelFlags
  std::vector<Vec3> normal;          // outward unit normal at rest (zero inside)
  std::vector<double> splat_radius;  // m (zero inside)
  std::vector<Vec3> external_force;  // the loads active at t = 0, per phyxel, N
  std::vector<LoadSpread> loads;     // every load, for loads that switch on or off
  std::vector<Vec3> initial_velocity;
  std::vector<Material> materials;  // object materials then inclusion materials
  std::vector<ObjectRange> objects;

  size_t size() const { return rest.size(); }
};

// Sum of the loads active at simulated time t, per phyxel.
std::vector<Vec3> external_forces_at(const PhyxelSet& set, double t);

struct SamplingOptions {
  // Refuse an object unless every phyxel has kMinMlsNeighbours neighbours within the support
  // radius, not all in one plane (scene.h). Off only in tests of how the solvers cope with
  // degenerate sets (a lone phyxel, a line, a plate).
  bool require_usable_fit = true;
};

// Samples every object of the scene on its lattice (corners included). Throws SceneError
// when an object has no phyxel, too few for a usable MLS fit (one line naming the object,
// what it sampled to and the spacing it needs), or would not fit in memory.
PhyxelSet sample_scene(const Scene& scene, const SamplingOptions& options = {});

}  // namespace phyxel
