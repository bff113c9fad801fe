// Steps of many substeps (a stiff material or a large dt: thousands to a million substeps per
// step) advanced so that a stop is seen within a fraction of a second of wall time, not only
// between steps.
#pragma once

#include <cstdint>
#include <functional>

#include <vector>

#include "engine/solver/solver.h"
#include "engine/surgery/tool_track.h"

namespace phyxel {

// Steps with at least this many substeps are advanced in polled chunks.
constexpr int64_t kLongStepSubsteps = 256;

// Advances `steps` steps of `substeps` substeps of dt, calling `stop` after each step and, in a
// step that takes about 2.5 x `poll_seconds` of wall time or more (the first is taken to), after
// each chunk of about `poll_seconds`. A stop in the middle of a step puts the solver back to the
// state at that step's start (read before it; Solver::set_state: the next advance continues
// exactly) and returns the whole steps done; a stop after a step returns the steps done; else
// `steps`. Chunks split the substeps of a solver without tools exactly (the same states bit for
// bit as one advance).
// `on_rate`, when set, is called once with the substeps per wall second measured over about
// `poll_seconds` of chunks (the first chunk left out).
int64_t advance_long_steps(Solver& solver, int64_t steps, int64_t substeps, double dt,
                           const std::function<bool()>& stop, double poll_seconds,
                           const std::function<void(double)>& on_rate = {});

// The same for scenes with tools or tearing, whose edits (cuts, tears, grips, aspiration) cannot
// be undone: chunks of about `poll_seconds`, the tools' motion set per chunk (`tools` may be
// empty) and their samples folded per step into `records` (steps x tools). A stop between steps
// returns the steps done; a stop in the middle of a step ends the advance there, leaving the
// solver inside that step (within_step: its substeps done), which the run does not write.
struct PolledToolSteps {
  int64_t steps = 0;        // whole steps done
  int64_t within_step = 0;  // > 0: stopped this many substeps into the next step
  std::vector<ToolStepRecord> records;
};
PolledToolSteps advance_long_tool_steps(Solver& solver, ToolTrack& tools, int64_t first_step,
                                        int64_t steps, int64_t substeps, double dt,
                                        const std::function<bool()>& stop, double poll_seconds);

}  // namespace phyxel
