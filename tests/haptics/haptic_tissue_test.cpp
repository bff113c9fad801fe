// A haptic tool whose loop runs far ahead of the physics (a physics stalled, or far slower than
// real time, while the hand moves on): the physics' tool goes to the device at its top speed
// (live_tool_speed, a tenth of the tissue's slowest p-wave speed) and the tissue stays stable.
// With the top speed fixed at 1 m/s this probe threw a phyxel of the brain past its p-wave
// speed 125 steps into the push (found by CI on a loaded 2-core machine).
#include <gtest/gtest.h>

#include <algorithm>

#include "engine/run/simulation.h"
#include "engine/solver/cpu_solver.h"

namespace phyxel {
namespace {

TEST(HapticTissue, AToolFarAheadOfItsPhysicsEntersAtItsTopSpeedAndTheTissueHolds) {
  const Scene scene = load_scene(PHYXEL_SOURCE_DIR "/scenes/probe_indent_haptic.json");
  const PhyxelSet set = sample_scene(scene);
  const std::unique_ptr<Solver> solver = make_cpu_solver(set, scene.simulation.gravity, 1);
  const double top = live_tool_speed(scene, scene.tools[0]);
  EXPECT_NEAR(top, 0.331, 1e-3);  // brain: c_p = 3.31 m/s
  // The device as a loop far ahead gives it: above the brain for 130 steps, then at once 2 cm
  // into it (the path's deepest pose).
  const double hold = 130 * scene.simulation.dt;
  RunOptions options;
  options.steps = 600;
  options.tool_pose = [hold](size_t, double t) {
    return ToolPose{Vec3(0, -0.012, t <= hold ? 0.0614 : 0.03), Vec3::UnitZ()};
  };
  double deepest = 1, fastest_tool = 0, previous_z = 0.0614, previous_t = 0;
  options.on_tool_step = [&](int64_t, double t, const std::vector<ToolStepRecord>& records) {
    const double z = records[0].pose.position.z();
    deepest = std::min(deepest, z);
    fastest_tool = std::max(fastest_tool, (previous_z - z) / (t - previous_t));
    previous_z = z;
    previous_t = t;
  };
  const RunResult r = run_simulation(scene, set, *solver, options);
  EXPECT_FALSE(r.unstable) << "step " << r.unstable_step << ", " << r.unstable_speed << " m/s";
  EXPECT_FALSE(r.non_finite);
  EXPECT_EQ(r.steps_done, 600);
  EXPECT_LE(fastest_tool, top * (1 + 1e-9));
  EXPECT_GT(fastest_tool, 0.99 * top);
  EXPECT_NEAR(deepest, 0.03, 1e-9);  // it got there
  EXPECT_GT(r.tools[0].max_contacts, 20u);
  double fastest_phyxel = 0;
  for (const Vec3& v : solver->read_state(false).velocity)
    fastest_phyxel = std::max(fastest_phyxel, v.norm());
  EXPECT_LT(fastest_phyxel, 3 * top);
}

}  // namespace
}  // namespace phyxel
