// What the renderer reads and what it builds once per scene.
//
// RenderInputs: the solver buffers the splat passes read each frame, exactly what the GPU
// solver exposes (gpu::SolverBuffers in compute/gpu_solver.h converts implicitly):
//   rest          vec4 per phyxel: x0.xyz (m), volume
//   displacement  vec4 per phyxel: u.xyz (m), 0
//   nbr_offset    uint[count + 1]: CSR row starts of the rest neighbour lists
//   nbr_index     uint[pairs]:     CSR neighbour indices (same object, sorted)
//   pair_weight   float[pairs], optional: 0 marks a severed (or removed) pair, which the
//                 deform pass leaves out; null: every pair is joined
// Nothing else of a solver is used.
//
// SurfelTable: the static per-surface-phyxel data (index, splat radius, support radius, rest
// normal, texture coordinates of the dome mapping and their tangential gradients), uploaded
// once. HostInputs: the same buffers built from a PhyxelSet for the CPU solver (rest and CSR
// uploaded once, the displacement once per frame, the pairs' alive mask after cuts).
#pragma once

#include <Eigen/Geometry>
#include <concepts>
#include <cstdint>
#include <memory>
#include <vector>

#include "compute/buffer.h"
#include "compute/recorder.h"
#include "engine/sampling/phyxel_set.h"
#include "engine/solver/neighbours.h"
#include "render/shaders/render_layout.h"

namespace phyxel::render {

struct RenderInputs {
  const gpu::Buffer* rest = nullptr;
  const gpu::Buffer* displacement = nullptr;
  const gpu::Buffer* nbr_offset = nullptr;
  const gpu::Buffer* nbr_index = nullptr;
  uint32_t count = 0;                        // phyxels
  const gpu::Buffer* pair_weight = nullptr;  // optional: float per CSR pair, 0 = severed
  // A GPU solver whose pairs exceed one binding holds the first nbr_index->size() / 4 of them
  // in nbr_index and pair_weight and the rest in these (gpu::PairBuffer); else null.
  const gpu::Buffer* nbr_index_hi = nullptr;
  const gpu::Buffer* pair_weight_hi = nullptr;

  RenderInputs() = default;
  RenderInputs(const gpu::Buffer* rest_, const gpu::Buffer* displacement_,
               const gpu::Buffer* nbr_offset_, const gpu::Buffer* nbr_index_, uint32_t count_,
               const gpu::Buffer* pair_weight_ = nullptr)
      : rest(rest_),
        displacement(displacement_),
        nbr_offset(nbr_offset_),
        nbr_index(nbr_index_),
        count(count_),
        pair_weight(pair_weight_) {}
  // From any struct with the same five members (gpu::SolverBuffers), and its pair_weight
  // when it has one.
  template <class B>
  requires requires(const B& b) {
    { b.rest } -> std::convertible_to<const gpu::Buffer*>;
    { b.displacement } -> std::convertible_to<const gpu::Buffer*>;
    { b.nbr_offset } -> std::convertible_to<const gpu::Buffer*>;
    { b.nbr_index } -> std::convertible_to<const gpu::Buffer*>;
    { b.count } -> std::convertible_to<uint32_t>;
  }
  RenderInputs(const B& b)  // NOLINT(google-explicit-constructor): the point is conversion
      : RenderInputs(b.rest, b.displacement, b.nbr_offset, b.nbr_index, b.count) {
    if constexpr (requires {
                    { b.pair_weight } -> std::convertible_to<const gpu::Buffer*>;
                  }) {
      pair_weight = b.pair_weight;
    }
    if constexpr (requires {
                    { b.nbr_index_hi } -> std::convertible_to<const gpu::Buffer*>;
                    { b.pair_weight_hi } -> std::convertible_to<const gpu::Buffer*>;
                  }) {
      nbr_index_hi = b.nbr_index_hi;
      pair_weight_hi = b.pair_weight_hi;
    }
  }
};

struct SurfelTable {
  std::vector<layout::SurfelStatic> surfels;
  Eigen::AlignedBox3d bounds;  // of the surface phyxels at rest
  uint32_t phyxels = 0;        // size of the PhyxelSet it was built from
};

// Every surface phyxel (kSurface, not kRemoved, splat radius > 0) of `set`, with texture
// coordinates from one dome per object (render/texture_map.h; axis +z). `material_mirror`
// (optional; environment_map.h's material_mirrors) gives the mirror fraction per material
// index, which goes into the flags (kSurfelMirrorShift) of the material's surfels.
SurfelTable build_surfel_table(const PhyxelSet& set,
                               const std::vector<double>& material_mirror = {});

// The input buffers for a solver whose state lives on the host (the CPU reference).
class HostInputs {
 public:
  HostInputs(gpu::Context& ctx, const PhyxelSet& set, const NeighbourLists& neighbours);
  // Copies u (one vec4 per phyxel) to the device-local displacement buffer (through a mapped
  // staging buffer; waits for the copy). Call between frames, not while one is in flight.
  void set_displacement(const std::vector<Vec3>& displacement);
  // Uploads the pairs' alive mask (Solver::pair_alive(): 1 per CSR pair still joined) as a
  // float 0/1 per pair; from then on inputs() carries it as pair_weight. Blocking and a whole
  // upload: call it only when the solver's severed_pairs() count changed since the last call.
  // Throws std::invalid_argument when the size is not the neighbour lists' pair count.
  void set_pair_alive(const std::vector<uint8_t>& alive);
  RenderInputs inputs() const;

 private:
  gpu::Context* ctx_;
  gpu::Buffer rest_, displacement_, nbr_offset_, nbr_index_, staging_, pair_weight_;
  std::unique_ptr<gpu::Recorder> recorder_;
  uint32_t count_ = 0;
  size_t pairs_ = 0;
};

}  // namespace phyxel::render
