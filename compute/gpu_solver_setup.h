// Host-side preparation of the GPU solver's buffers from a PhyxelSet (double) in the float
// layout of compute/shaders/layout.h, and the device-memory bound of a set. Private to
// compute/gpu_solver*.cpp.
#pragma once

#include <cstdint>
#include <vector>

#include "compute/shaders/layout.h"
#include "engine/sampling/phyxel_set.h"

namespace phyxel::gpu {

struct SolverSetup {
  std::vector<layout::SolverClass> classes;  // one per (object, material) in use
  std::vector<layout::vec4> rest;            // x0 (world), volume
  std::vector<layout::vec4> local;           // hi = float(x0 - object centre), kappa (0 here)
  std::vector<layout::vec4> rest_lo;         // lo = float((x0 - centre) - hi), 0
  std::vector<layout::vec4> ext;             // m g + load, m
  std::vector<layout::vec4> velocity;        // initial v (0 for fixed phyxels), 0
  std::vector<uint32_t> flags;               // PhyxelFlags | class << kFlagClassShift
};

// Throws std::invalid_argument when the set has more (object, material) combinations than
// the flags word can index.
SolverSetup prepare_solver_setup(const PhyxelSet& set, const Vec3& gravity);

// Upper bound of the pair count of a lattice-sampled set: per object, its active phyxels times
// the lattice points (other than the origin) strictly inside the support sphere.
uint64_t lattice_pair_bound(const PhyxelSet& set);

// Buckets of the neighbour search's hash: a power of two, at least twice the phyxel count.
uint32_t hash_buckets(size_t phyxels);

// Bytes of device memory per phyxel and per pair the solver keeps, and what the neighbour
// search needs on top for a while (see GpuSolver::required_device_bytes).
inline constexpr uint64_t kPersistentBytesPerPhyxel =
    16 /*rest*/ + 16 /*local*/ + 32 /*two displacements*/ + 16 /*v*/ + 16 /*f*/ + 16 /*ext*/ +
    4 /*flags*/ + 32 /*A^-1*/ + 32 /*residual*/ + 48 /*D*/ + 4 /*offset*/ + 16 /*energy*/ +
    4 /*von Mises*/ + 8 /*stress and force pass lists*/ + 4 /*principal stress (tearing)*/;
inline constexpr uint64_t kBytesPerPair = 4 /*index*/ + 4 /*weight*/;
inline constexpr uint64_t kSearchBytesPerPhyxel =
    16 /*rest_lo*/ + 16 /*cell*/ + 4 /*slot*/ + 4 /*sorted*/ + 4 /*count*/;
inline constexpr uint64_t kSearchBytesPerBucket = 8;  // count and start

}  // namespace phyxel::gpu
