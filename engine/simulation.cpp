#include "engine/simulation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "engine/vtp_writer.h"

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

namespace {

std::string points_name(int64_t step) {
  char name[64];
  std::snprintf(name, sizeof name, "points_%06lld.vtp", static_cast<long long>(step));
  return name;
}

double max_norm(const std::vector<Vec3>& u) {
  double m = 0;
  for (const Vec3& x : u) m = std::max(m, x.norm());
  return m;
}

}  // namespace

RunResult run_simulation(const Scene& scene, const PhyxelSet& set, Solver& solver,
                         const RunOptions& options) {
  RunResult result;
  result.plan = plan_time_step(scene, set);
  const int64_t total = options.steps;
  const int64_t every = scene.output.every;
  const UntilRest& rest = scene.simulation.until_rest;
  // Energy and finiteness are looked at every `check` steps (a readback on the GPU).
  const int64_t check = rest.enabled ? std::clamp<int64_t>(rest.for_steps / 10, 1, 100) : 100;
  int64_t below_since = -1;

  auto write_points = [&](int64_t step) {
    if (options.out_dir.empty()) return;
    const PointState state = solver.read_state(true);
    const std::string name = points_name(step);
    write_points_vtp(options.out_dir / name, set, state, scene.output.binary);
    result.outputs.push_back(name);
  };

  const auto start = std::chrono::steady_clock::now();
  int64_t step = 0;
  while (step < total) {
    // Advance to the next step at which something has to be looked at.
    int64_t next = std::min(total, (step / check + 1) * check);
    if (every > 0) next = std::min(next, (step / every + 1) * every);
    solver.advance((next - step) * result.plan.substeps, result.plan.dt_used);
    step = next;
    if (options.progress) options.progress(step, total);
    if (step % check == 0 || step == total) {
      const long bad = solver.first_non_finite();
      if (bad >= 0) {
        result.non_finite = true;
        result.non_finite_step = step;
        result.non_finite_phyxel = bad;
        break;
      }
      if (rest.enabled) {
        const double ke = solver.energies().kinetic;
        if (ke >= rest.kinetic_energy_below) {
          below_since = -1;
        } else if (below_since < 0) {
          below_since = step;
        }
        if (below_since >= 0 && step - below_since >= rest.for_steps) {
          result.stopped_at_rest = true;
        }
      }
    }
    if (every > 0 && step % every == 0 && step != total && !result.stopped_at_rest)
      write_points(step);
    if (result.stopped_at_rest) break;
  }
  result.steps_done = step;
  result.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!result.non_finite) {
    write_points(step);
    result.energies = solver.energies();
    result.max_displacement = max_norm(solver.read_state(false).displacement);
  }
  return result;
}

}  // namespace phyxel
