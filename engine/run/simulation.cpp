#include "engine/run/simulation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "engine/run/run_loop.h"

namespace phyxel {

TimeStepPlan plan_time_step(const Scene& scene, const PhyxelSet& set) {
  TimeStepPlan plan;
  plan.dt_requested = scene.simulation.dt;
  double bound = std::numeric_limits<double>::infinity();
  std::vector<double> speed(set.materials.size());
  for (size_t m = 0; m < set.materials.size(); ++m) speed[m] = p_wave_speed(set.materials[m]);
  for (size_t i = 0; i < set.size(); ++i) {
    if (set.flags[i] & (kFixed | kRemoved)) continue;
    bound = std::min(bound, set.objects[set.object[i]].spacing / speed[set.material[i]]);
  }
  plan.dt_stable = scene.simulation.courant * bound;
  plan.substeps = 1;
  if (plan.dt_requested > plan.dt_stable)
    plan.substeps =
        static_cast<int64_t>(std::ceil(plan.dt_requested / plan.dt_stable * (1 - 1e-12)));
  plan.dt_used = plan.dt_requested / static_cast<double>(plan.substeps);
  if (plan.substeps > 1) {
    char text[256];
    std::snprintf(text, sizeof text,
                  "requested dt %.4g s exceeds the stable step %.4g s (courant %.3g x spacing / "
                  "p-wave speed); each step is split into %lld substeps of %.4g s",
                  plan.dt_requested, plan.dt_stable, scene.simulation.courant,
                  static_cast<long long>(plan.substeps), plan.dt_used);
    plan.reason = text;
  }
  return plan;
}

// A thin driver over the run loop (run_loop.h): its steps to the end.
RunResult run_simulation(const Scene& scene, const PhyxelSet& set, Solver& solver,
                         const RunOptions& options) {
  RunLoop loop(scene, set, solver, options);
  while (loop.running()) loop.step();
  return loop.finish();
}

std::vector<ToolStepRecord> advance_with_tools(Solver& solver, ToolTrack& tools, int64_t first,
                                               int64_t steps, int64_t substeps, double dt,
                                               const std::vector<int64_t>& pauses,
                                               const std::function<void(int64_t)>& at,
                                               const std::function<void()>& ready) {
  auto advance = [&] {
    if (pauses.empty())
      solver.advance(steps * substeps, dt);
    else
      solver.advance_paused(steps * substeps, dt, pauses, at);
  };
  if (tools.empty()) {
    advance();
    return {};
  }
  Tools& facet = need(solver.tools(), solver, "simulate tools");
  facet.set_tool_motion(tools.motions(first * substeps, steps * substeps, dt));
  if (ready) ready();
  advance();
  return tools.fold(facet.tool_samples(), steps, substeps);
}

Runaway find_runaway(const PhyxelSet& set, const std::vector<Vec3>& velocity) {
  std::vector<double> wave_speed(set.materials.size());
  for (size_t m = 0; m < set.materials.size(); ++m) wave_speed[m] = p_wave_speed(set.materials[m]);
  Runaway r;
  for (size_t i = 0; i < set.size() && i < velocity.size(); ++i) {
    const double v2 = velocity[i].squaredNorm();
    const double c = wave_speed[set.material[i]];
    if (v2 > c * c) {
      r.phyxel = static_cast<long>(i);
      r.speed = std::sqrt(v2);
      r.wave_speed = c;
      break;
    }
  }
  return r;
}

}  // namespace phyxel
