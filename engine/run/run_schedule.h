// What the run loop (engine/run/simulation.cpp) and its --explain (explain.cpp) both derive
// from a scene: when loads switch, whether the grasp passes run, how often the state is
// checked.
#pragma once

#include <cstdint>
#include <vector>

#include "engine/run/simulation.h"

namespace phyxel {

// Steps (of the requested size) at which some load switches on or off, inside (0, total).
std::vector<int64_t> load_event_steps(const PhyxelSet& set, double step_time, int64_t total);

// Whether a tool grasps (engine/solver/grasper.h): the grasp passes run only then.
bool has_grasper(const Scene& scene);

// Substeps per advance while tools move for a body of `phyxels` phyxels:
// options.tool_chunk_substeps where set, else kSmallToolChunk up to kSmallBodyPhyxels, where
// each advance's fixed part (its broad phase, its first substep's own passes, the host's turn)
// costs more than a longer chunk's wider margin, and kToolChunk above (docs/performance.md).
constexpr int64_t kToolChunk = 64, kSmallToolChunk = 128;
constexpr size_t kSmallBodyPhyxels = 100000;
int64_t tool_chunk_substeps(const RunOptions& options, size_t phyxels);

// Steps per advance while tools move (the tool chunks' grid from step 0, at whose lines the
// aspirator acts): tool_chunk_substeps over `substeps` per step, and where an aspirator can
// tear tissue at most its suction.interval (steps of `step_time` s), so that the aspiration
// grid is the same whatever the substeps (docs/suction.md, "Resolution"); at least 1; 0
// without tools.
int64_t tool_chunk_steps(const Scene& scene, const RunOptions& options, size_t phyxels,
                         int64_t substeps, double step_time);

// Steps between the run loop's checks (rest, sleep, runaway): options.check_every when set,
// else 100, fewer when rest or sleep must be decided sooner. Where tools move (`tool_chunk` >
// 0) and no check decides rest or sleep, the multiple of the chunk nearest 100: a check then
// ends no advance off the chunks' grid (each such end a drain of the GPU and a read-back).
int64_t check_interval(const Scene& scene, const RunOptions& options, bool sleeping,
                       int64_t tool_chunk);

}  // namespace phyxel
