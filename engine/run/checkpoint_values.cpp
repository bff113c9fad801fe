#include "engine/run/checkpoint_values.h"

#include <cmath>
#include <string>
#include <vector>

namespace phyxel {
namespace {

bool finite(const Vec3& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

bool all_finite(const std::vector<Vec3>& values) {
  for (const Vec3& v : values)
    if (!finite(v)) return false;
  return true;
}

bool stats_ok(const ToolRunStats& s) {
  for (double x : {s.max_force, s.max_cut_force, s.max_feedback, s.max_friction, s.max_depth})
    if (!std::isfinite(x) || x < 0) return false;
  return finite(s.last_force) && s.steps_in_contact >= 0 && s.cutting_substeps >= 0;
}

}  // namespace

void check_checkpoint_values(const Checkpoint& c, const std::filesystem::path& file,
                             const Scene& scene, const PhyxelSet& set) {
  const auto fail = [&](const std::string& what) {
    throw CheckpointError(file.string() + ": corrupt checkpoint: " + what +
                          " (edited since it was written?); resume from a checkpoint phyxel "
                          "wrote, or start the run again");
  };
  if (c.step < 0 || !std::isfinite(c.time) || !(c.dt_requested > 0) || c.substeps < 1 ||
      c.check_every < 1 || c.checkpoint_every < 0 || c.total < c.step)
    fail("its step, time or schedule is out of range");
  if (!all_finite(c.displacement) || !all_finite(c.velocity) || !all_finite(c.last_check_u))
    fail("a non-finite displacement or velocity");
  for (uint8_t a : c.awake)
    if (a > 1) fail("an object's sleep flag is neither 0 nor 1");
  if (c.loads_applied < 0 || c.sleeps < 0 || c.wakes < 0 || c.load_changes < 0)
    fail("a negative count");
  if (c.tool_stats.size() != scene.tools.size() || c.tool_poses.size() != scene.tools.size())
    fail("it holds " + std::to_string(c.tool_stats.size()) + " tools, the scene " +
         std::to_string(scene.tools.size()));
  for (size_t k = 0; k < c.tool_stats.size(); ++k) {
    if (c.tool_stats[k].name != scene.tools[k].name)
      fail("tool " + std::to_string(k) + " is not the scene's '" + scene.tools[k].name + "'");
    if (!stats_ok(c.tool_stats[k]) || !finite(c.tool_poses[k].position) ||
        !finite(c.tool_poses[k].axis) || !(c.tool_poses[k].axis.norm() > 0))
      fail("tool '" + scene.tools[k].name + "' has a non-finite or negative value");
  }
  const size_t n = set.size();
  for (const SeveredPair& p : c.severed)
    if (p.i >= n || p.j >= n || p.i == p.j || !std::isfinite(p.t))
      fail("a severed pair (" + std::to_string(p.i) + ", " + std::to_string(p.j) +
           ") outside the scene's " + std::to_string(n) + " phyxels");
  for (const Grip& g : c.grips)
    for (const GripEntry& e : g.held)
      if (e.phyxel >= n || !finite(e.offset)) fail("a grip holds a phyxel out of range");
  const AspiratorState& a = c.aspiration;
  for (const uint32_t i : a.removed)
    if (i >= n) fail("an aspirated phyxel outside the scene's phyxels");
  for (const std::vector<double>* v : {&a.removed_mass, &a.removed_volume})
    for (double x : *v)
      if (!std::isfinite(x) || x < 0) fail("a negative or non-finite aspirated mass or volume");
  if (a.events < 0 || !std::isfinite(a.max_radius)) fail("a bad aspiration count or radius");
}

}  // namespace phyxel
