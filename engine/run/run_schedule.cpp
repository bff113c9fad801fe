#include "engine/run/run_schedule.h"

#include <algorithm>
#include <cmath>

namespace phyxel {

std::vector<int64_t> load_event_steps(const PhyxelSet& set, double step_time, int64_t total) {
  std::vector<int64_t> steps;
  for (const LoadSpread& load : set.loads)
    for (const double t : {load.from, load.until}) {
      if (!(t > 0) || !std::isfinite(t)) continue;
      const auto k = static_cast<int64_t>(std::ceil(t / step_time - 1e-9));
      if (k > 0 && k < total) steps.push_back(k);
    }
  std::sort(steps.begin(), steps.end());
  steps.erase(std::unique(steps.begin(), steps.end()), steps.end());
  return steps;
}

bool has_grasper(const Scene& scene) {
  return std::any_of(scene.tools.begin(), scene.tools.end(),
                     [](const ToolDesc& t) { return t.grasp.grasps(); });
}

int64_t tool_chunk_substeps(const RunOptions& options, size_t phyxels) {
  if (options.tool_chunk_substeps > 0) return options.tool_chunk_substeps;
  return phyxels <= kSmallBodyPhyxels ? kSmallToolChunk : kToolChunk;
}

int64_t tool_chunk_steps(const Scene& scene, const RunOptions& options, size_t phyxels,
                         int64_t substeps, double step_time) {
  if (scene.tools.empty()) return 0;
  int64_t chunk = tool_chunk_substeps(options, phyxels) / std::max<int64_t>(1, substeps);
  if (scene.tearing_possible() && step_time > 0)
    for (const ToolDesc& t : scene.tools)
      if (t.suction.sucks())
        chunk = std::min(
            chunk, static_cast<int64_t>(std::floor(t.suction.interval / step_time * (1 + 1e-12))));
  return std::max<int64_t>(1, chunk);
}

int64_t check_interval(const Scene& scene, const RunOptions& options, bool sleeping,
                       int64_t tool_chunk) {
  if (options.check_every > 0) return options.check_every;
  int64_t check = 100;
  const UntilRest& rest = scene.simulation.until_rest;
  if (!rest.enabled && !sleeping && tool_chunk > 0)
    return std::max<int64_t>(1, std::llround(100.0 / double(tool_chunk))) * tool_chunk;
  if (rest.enabled) check = std::min(check, std::clamp<int64_t>(rest.for_steps / 10, 1, 100));
  if (sleeping)
    check = std::min(check, std::clamp<int64_t>(scene.simulation.sleep.for_steps / 10, 1, 100));
  return check;
}

}  // namespace phyxel
