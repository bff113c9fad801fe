// The SCNI band round a blade's cut (docs/cutting.md, "Stiffness of a cut body"): the quads the
// blades swept while cutting an object with cut_band > 0, which phyxels join the band, and their
// cells' smoothed-gradient boxes (scni_band.h), built in double. Shared by the CPU solver
// (cpu_solver_band.cpp) and the GPU solver (compute/gpu_solver_band.cpp), which integrate the
// same boxes, each in its own precision.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "engine/geometry/vec3.h"
#include "engine/sampling/phyxel_set.h"
#include "engine/solver/cut_band_state.h"
#include "engine/solver/scni_band.h"

namespace phyxel {

class CutBand {
 public:
  // One box's smoothed gradient G = sum_k u_node[k] coeff[k]^T and its energy weight.
  struct Box {
    double volume = 0;
    std::vector<uint32_t> node;
    std::vector<Vec3> coeff;
  };
  struct Cell {
    uint32_t phyxel = 0;
    std::vector<Box> box;   // empty until built
    bool dirty = true;      // quads reached it since it was built
    size_t built_with = 0;  // quads stored when it was built (its boxes saw those)
  };
  // Phyxel k's slot `slot` in box `box` of cell `cell` (the transposed lists of the force).
  struct GatherEntry {
    uint32_t cell, box, slot;
  };
  struct Refresh {
    std::vector<uint32_t> built;   // cells (re)built, ascending
    std::vector<uint32_t> joined;  // their phyxels whose cell was built for the first time
  };

  // volume: the solver's quadrature volume per phyxel (the boxes' weights add up to it).
  CutBand(const PhyxelSet& set, const std::vector<double>& volume);
  bool on() const { return on_; }  // an object has cut_band > 0

  const std::vector<std::array<Vec3, 4>>& quads() const { return quads_; }
  // Keeps the quad a blade of `reach` swept in a substep, unless it has no area (more than
  // 1e-12 reach^2: a blade that did not move cut no surface). Both solvers' cut passes call it.
  void add_cut(const std::array<Vec3, 4>& quad, double reach);
  // threads: for the cells built (0: OpenMP's count).
  // At a new chunk of tool motion: builds the cells the quads of the chunks before the last
  // one reach (the cut has passed them), unless a quad of the last chunk reaches them too.
  Refresh start_chunk(const std::vector<uint32_t>& flags, int threads);
  // With no blade left in the cut: builds every cell the quads reach.
  Refresh refresh_all(const std::vector<uint32_t>& flags, int threads) {
    return refresh(quads_.size(), flags, threads);
  }

  // For checkpoints: the state, and the band rebuilt from one (the cells built as they were;
  // throws std::invalid_argument naming what does not fit this set).
  CutBandState state() const;
  Refresh restore(const CutBandState& state, const std::vector<uint32_t>& flags, int threads);

  const std::vector<Cell>& cells() const { return cells_; }
  // Whether phyxel i's cell is integrated by the band (built at least once).
  bool in_band(size_t i) const {
    return !cell_of_.empty() && cell_of_[i] >= 0 && !cells_[size_t(cell_of_[i])].box.empty();
  }
  // Per phyxel k: its entries gather[gather_offset[k] .. gather_offset[k + 1]) (empty: none).
  const std::vector<uint32_t>& gather_offset() const { return gather_offset_; }
  const std::vector<GatherEntry>& gather() const { return gather_; }

 private:
  // Builds the cells the quads [quads_built_, upto) reach (flags: PhyxelFlags per phyxel).
  Refresh refresh(size_t upto, const std::vector<uint32_t>& flags, int threads);
  // From the first `quads` quads stored (all of them when it is built as the cut goes on).
  void build_cell(size_t cell, const PointGrid& grid, const std::vector<uint32_t>& flags,
                  size_t quads);
  void build_cells(const std::vector<uint32_t>& cells, const std::vector<uint32_t>& flags,
                   int threads);
  void build_gather();

  bool on_ = false;
  std::vector<Vec3> rest_;
  std::vector<uint32_t> object_;
  std::vector<double> volume_;
  std::vector<double> band_width_, spacing_, support_;  // per object (width 0: none)
  double max_support_ = 0;
  std::vector<Vec3> object_lo_, object_hi_;  // per object: the bounds of its rest positions
  std::vector<std::array<Vec3, 4>> quads_;
  size_t quads_built_ = 0, quads_before_chunk_ = 0;
  std::vector<int32_t> cell_of_;  // per phyxel: its cell, -1 (empty while no band)
  std::vector<Cell> cells_;
  std::vector<uint32_t> gather_offset_;
  std::vector<GatherEntry> gather_;
};

}  // namespace phyxel
