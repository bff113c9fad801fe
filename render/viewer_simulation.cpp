#include "render/viewer_simulation.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <utility>

namespace phyxel::render {
namespace {

// The viewer runs until its window closes: a total no session reaches.
constexpr int64_t kEndless = int64_t(1) << 60;

}  // namespace

ViewerSimulation::ViewerSimulation(const Scene& scene, const PhyxelSet& set, Solver& solver,
                                   Hooks hooks)
    : hooks_(std::move(hooks)), loop_(scene, set, solver, run_options()) {}

RunOptions ViewerSimulation::run_options() {
  RunOptions options;
  options.steps = kEndless;
  options.tool_pose = hooks_.tool_pose;
  options.on_tool_step = [this](int64_t, double t, const std::vector<ToolStepRecord>& records) {
    felt_ = records;
    if (hooks_.on_tool_step) hooks_.on_tool_step(t, records);
  };
  options.on_aspiration = hooks_.on_aspiration;
  return options;
}

void ViewerSimulation::advance(int64_t steps) {
  const int64_t until = loop_.steps_done() + steps;
  while (halted_.empty() && loop_.steps_done() < until) {
    if (loop_.result().stopped_at_rest) loop_.extend(loop_.total());  // runs on at rest
    loop_.step(until);
    check_state();
  }
}

// What the loop's last check found, else its stability check now (reductions; the state is read
// back only for a phyxel faster than the slowest wave speed).
void ViewerSimulation::check_state() {
  const RunResult& r = loop_.result();
  if (!r.non_finite && !r.unstable) loop_.check_stability();
  if (r.non_finite) return halt("non-finite", r.non_finite_step, r.non_finite_phyxel, 0);
  if (r.unstable) return halt("runaway", r.unstable_step, r.unstable_phyxel, r.unstable_speed);
}

void ViewerSimulation::halt(const char* what, int64_t step, long phyxel, double speed) {
  char text[256];
  std::snprintf(text, sizeof text, "halted: %s at step %lld, phyxel %ld", what,
                static_cast<long long>(step), phyxel);
  halted_ = text;
  if (speed > 0) {
    std::snprintf(text, sizeof text, " (%.3g m/s)", speed);
    halted_ += text;
  }
  std::fprintf(stderr,
               "phyxel view: %s; the simulation is unstable: try a smaller simulation.courant "
               "or dt, or smaller loads\n",
               halted_.c_str());
}

}  // namespace phyxel::render
