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

// Steps between the run loop's checks (rest, sleep, runaway): options.check_every when set,
// else 100, fewer when rest or sleep must be decided sooner.
int64_t check_interval(const Scene& scene, const RunOptions& options, bool sleeping);

}  // namespace phyxel
