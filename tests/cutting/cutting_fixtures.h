// Scenes and drivers shared by the cutting and tearing tests: a clamped beam, a scalpel that
// crosses it, and a bar pulled apart by end loads.
#pragma once

#include <algorithm>
#include <functional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "../physics/physics_fixtures.h"
#include "engine/run/simulation.h"
#include "engine/solver/cpu_solver.h"
#include "engine/surgery/tool_track.h"

namespace phyxel::test {

// Moves the scene's tools over its first `steps` steps as the run loop does, `chunk` steps per
// advance: set_tools, then per chunk the motions, the advance, and after(the chunk's samples).
inline void advance_tools_in_chunks(
    Solver& solver, const Scene& scene, const PhyxelSet& set, int64_t steps, int64_t chunk,
    const std::function<void(const std::vector<ToolContactSample>&)>& after) {
  const TimeStepPlan plan = plan_time_step(scene, set);
  ToolTrack track(scene.tools, {});
  Tools& tools = *solver.tools();
  tools.set_tools(contact_tools(scene.tools));
  for (int64_t s = 0; s < steps; s += chunk) {
    const int64_t n = std::min<int64_t>(chunk, steps - s) * plan.substeps;
    tools.set_tool_motion(track.motions(s * plan.substeps, n, plan.dt_used));
    solver.advance(n, plan.dt_used);
    after(tools.tool_samples());
  }
}

// A beam along x, [0, 0.04] x [0, 0.01] x [0, 0.01] m, spacing 2 mm, clamped at x <= 0.5 mm.
inline Scene clamped_beam(double young = 5e4, double damping = 0) {
  Scene scene =
      box_scene(Vec3(0, 0, 0), Vec3(0.04, 0.01, 0.01), 0.002, tissue(young, 0.3, damping));
  scene.objects[0].fixed.push_back(box_shape(Vec3(-1, -1, -1), Vec3(0.0005, 1, 1)));
  scene.simulation.dt = 1e-4;
  scene.simulation.gravity = Vec3(0, 0, -9.81);
  return scene;
}

// A scalpel whose vertical blade (tip at z = tip_z, `length` up) crosses the plane x = x_cut
// along +y from y = -3 mm to y = 13 mm during [t0, t0 + duration].
inline ToolDesc crossing_scalpel(double x_cut, double tip_z, double length, double t0,
                                 double duration, double threshold = 0) {
  ToolDesc t;
  t.name = "scalpel";
  t.type = ToolDesc::Type::Scalpel;
  t.shape.type = ToolShape::Type::Capsule;
  t.shape.radius = 0.0002;
  t.shape.length = length;
  t.path = {{t0, Vec3(x_cut, -0.003, tip_z), Vec3::UnitZ()},
            {t0 + duration, Vec3(x_cut, 0.013, tip_z), Vec3::UnitZ()}};
  t.blade.length = length;
  t.blade.edge = Vec3::UnitY();
  t.blade.reference_axis = Vec3::UnitZ();
  t.blade.threshold = threshold;
  return t;
}

// Steps a CPU solver with the scene's tools along their paths, one substep per step.
template <class Real>
struct ToolStepper {
  CpuSolver<Real>& solver;
  ToolTrack track;
  double dt;
  int64_t step = 0;
  ToolStepper(CpuSolver<Real>& s, const std::vector<ToolDesc>& tools, double dt_)
      : solver(s), track(tools, {}), dt(dt_) {
    solver.set_tools(contact_tools(tools));
  }
  void run(int64_t steps) {
    for (int64_t k = 0; k < steps; ++k, ++step) {
      solver.set_tool_motion(track.motions(step, 1, dt), Real(dt));
      solver.step(Real(dt));
    }
  }
};

// A 4 x 1 x 1 cm bar pulled apart by equal and opposite end loads (no clamp, so no stress
// concentration at a support), damped to follow the load quasi-statically.
struct PulledBar {
  static constexpr double kArea = 1e-4;        // m^2
  static constexpr double kTearStress = 1000;  // Pa: it tears under 0.1 N
  Scene scene;
  PhyxelSet set;
  std::vector<Vec3> unit_load;  // per phyxel, for 1 N at each end
  double dt = 0;

  explicit PulledBar(bool with_strength = true) {
    scene = box_scene(Vec3(0, -0.005, -0.005), Vec3(0.04, 0.005, 0.005), 0.0025,
                      tissue(1e5, 0.3, 600), 2.0);
    Load pull, push;
    pull.region = box_shape(Vec3(0.0399, -1, -1), Vec3(1, 1, 1));
    pull.force = Vec3(1, 0, 0);
    push.region = box_shape(Vec3(-1, -1, -1), Vec3(0.0001, 1, 1));
    push.force = Vec3(-1, 0, 0);
    scene.objects[0].loads = {pull, push};
    if (with_strength) scene.objects[0].material.tear_stress = kTearStress;
    set = sample_scene(scene);
    unit_load = external_forces_at(set, 0);
    dt = plan_time_step(scene, set).dt_stable;
  }

  std::vector<Vec3> load(double newtons) const {
    std::vector<Vec3> f(unit_load.size());
    for (size_t i = 0; i < f.size(); ++i) f[i] = newtons * unit_load[i];
    return f;
  }
};

// The phyxel with the most pairs (the first such) left with one, to q (its first neighbour),
// by tears (torn) or by removals of its other neighbours (docs/tearing.md, "A phyxel left
// without a fit"). Returns (p, q).
inline std::pair<uint32_t, uint32_t> leave_one_pair(Solver& solver, bool torn) {
  const NeighbourLists& nbr = solver.neighbours();
  uint32_t p = 0;
  for (uint32_t i = 0; i + 1 < nbr.offset.size(); ++i)
    if (nbr.offset[i + 1] - nbr.offset[i] > nbr.offset[p + 1] - nbr.offset[p]) p = i;
  const uint32_t q = nbr.index[nbr.offset[p]];
  std::vector<SeveredPair> pairs;
  std::vector<uint32_t> others;
  for (uint32_t k = nbr.offset[p] + 1; k < nbr.offset[p + 1]; ++k) {
    const uint32_t j = nbr.index[k];
    pairs.push_back({std::min(p, j), std::max(p, j), 0.5f, true});
    others.push_back(j);
  }
  if (torn)
    solver.cutting()->sever_pairs(pairs);
  else
    solver.removal()->remove_phyxels(others);
  return {p, q};
}

// A 2 x 2 x 1 cm block of brain-like tissue on a fixed base, an aspirator (20 kPa) on the middle
// of its top, held there for 0.15 s, or (descending) sucking its way 6 mm down over 0.3 s.
inline std::string suction_block_json(double tear_stress, bool descending = false,
                                      double pressure = 20000) {
  std::ostringstream j;
  j << R"({"simulation": {"dt": 1e-3, "steps": 300, "gravity": [0, 0, 0]},
  "objects": [{"name": "brain", "shape": {"type": "box", "min": [0, 0, 0], "max": [0.02, 0.02, 0.01]},
    "spacing": 0.002,
    "material": {"young": 5e3, "poisson": 0.3, "density": 1000, "damping": 40,
                 "tear_stress": )"
    << tear_stress << R"(},
    "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.0001]}]}],
  "tools": [{"name": "aspirator", "type": "suction",
    "shape": {"type": "capsule", "radius": 0.0015, "length": 0.05},
    "path": [{"t": 0, "position": [0.01, 0.01, 0.0117], "axis": [0, 0, 1]})"
    << (descending ? R"(, {"t": 0.3, "position": [0.01, 0.01, 0.0057], "axis": [0, 0, 1]})" : "")
    << R"(],
    "suction": {"pressure": )"
    << pressure << R"(, "reach": 0.005, "until": )" << (descending ? 0.3 : 0.15) << R"(}}],
  "output": {"every": 0}})";
  return j.str();
}

}  // namespace phyxel::test
