// The viewer's simulation (render/viewer_simulation.h) without a window: the run loop of
// `phyxel run` advanced a frame's steps at a time gives run_simulation's state bit for bit, a
// runaway halts it with the step and phyxel, and a rest does not end it.
#include <gtest/gtest.h>

#include <vector>

#include "engine/run/simulation.h"
#include "render/viewer_simulation.h"

namespace phyxel::render {
namespace {

// A block pressed by a probe on a path, with a load switching on at step 20.
constexpr const char* kPressedBlock = R"({
  "simulation": {"dt": 2e-4, "steps": 150, "gravity": [0, 0, -9.81]},
  "objects": [{
    "name": "block",
    "shape": {"type": "box", "min": [0, 0, 0], "max": [0.04, 0.04, 0.02]},
    "spacing": 0.004,
    "material": {"young": 3000, "poisson": 0.45, "density": 1040, "damping": 20},
    "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.001]}],
    "loads": [{"region": {"type": "box", "min": [-1, -1, 0.019], "max": [0.01, 1, 1]},
               "force": [0, 0, -0.05], "from": 0.004}]
  }],
  "tools": [{
    "name": "probe", "type": "probe", "shape": {"type": "sphere", "radius": 0.005},
    "path": [{"t": 0, "position": [0.02, 0.02, 0.027]}, {"t": 0.02, "position": [0.02, 0.02, 0.016]}]
  }]
})";

constexpr const char* kRunaway = R"({
  "simulation": {"dt": 5e-5, "steps": 4000, "gravity": [0, 0, 0]},
  "objects": [{
    "name": "beam",
    "shape": {"type": "box", "min": [0, -0.01, -0.01], "max": [0.1, 0.01, 0.01]},
    "spacing": 0.005,
    "material": {"young": 1e6, "poisson": 0.3, "density": 1000},
    "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [0.0005, 1, 1]}],
    "loads": [{"region": {"type": "box", "min": [0.09, -1, -1], "max": [1, 1, 1]},
               "force": [0, 0, -1e6]}]
  }]
})";

TEST(ViewerSimulation, StepsAsPhyxelRunDoesWhateverTheFrames) {
  const Scene scene = parse_scene(kPressedBlock, "pressed_block.json");
  const PhyxelSet set = sample_scene(scene);
  const int64_t steps = scene.simulation.steps;

  auto run_solver = make_cpu_solver(set, scene.simulation.gravity, 1);
  RunOptions options;
  options.steps = steps;
  std::vector<ToolStepRecord> last;
  options.on_tool_step = [&last](int64_t, double, const std::vector<ToolStepRecord>& r) {
    last = r;
  };
  const RunResult run = run_simulation(scene, set, *run_solver, options);
  ASSERT_EQ(run.steps_done, steps);
  ASSERT_EQ(run.load_changes, 1);

  auto view_solver = make_cpu_solver(set, scene.simulation.gravity, 1);
  int tool_steps = 0;
  ViewerSimulation::Hooks hooks;
  hooks.on_tool_step = [&tool_steps](double, const std::vector<ToolStepRecord>&) { ++tool_steps; };
  ViewerSimulation view(scene, set, *view_solver, hooks);
  // Frames of uneven lengths, as the wall clock and the n key give them.
  const int64_t frames[] = {1, 1, 3, 17, 2, 40, 7, 64, 5};
  for (size_t f = 0; view.step() < steps; ++f)
    view.advance(std::min(frames[f % std::size(frames)], steps - view.step()));
  ASSERT_EQ(view.step(), steps);
  EXPECT_TRUE(view.halted().empty());
  EXPECT_EQ(tool_steps, steps);

  const PointState a = run_solver->read_state(false), b = view_solver->read_state(false);
  for (size_t i = 0; i < set.size(); ++i) {
    ASSERT_EQ(a.displacement[i], b.displacement[i]) << "phyxel " << i;
    ASSERT_EQ(a.velocity[i], b.velocity[i]) << "phyxel " << i;
  }
  ASSERT_EQ(view.felt().size(), 1u);
  ASSERT_GT(last[0].contacts, 0u) << "the probe must press the block for the test to mean much";
  EXPECT_EQ(view.felt()[0].contacts, last[0].contacts);
  EXPECT_EQ(view.felt()[0].force, last[0].force);
}

TEST(ViewerSimulation, HaltsARunawayAndSaysWhere) {
  const Scene scene = parse_scene(kRunaway, "runaway.json");
  const PhyxelSet set = sample_scene(scene);
  auto solver = make_cpu_solver(set, scene.simulation.gravity, 1);
  ViewerSimulation view(scene, set, *solver, {});
  view.advance(2000);
  ASSERT_FALSE(view.halted().empty());
  EXPECT_LT(view.step(), 2000);
  EXPECT_EQ(view.halted().rfind("halted: ", 0), 0u) << view.halted();
  EXPECT_NE(view.halted().find("at step " + std::to_string(view.step()) + ", phyxel "),
            std::string::npos)
      << view.halted();
  const int64_t halted_at = view.step();
  view.advance(100);
  EXPECT_EQ(view.step(), halted_at);
}

TEST(ViewerSimulation, RunsOnPastRest) {
  Scene scene = parse_scene(kPressedBlock, "pressed_block.json");
  scene.tools.clear();
  scene.objects[0].loads.clear();
  scene.simulation.gravity = Vec3::Zero();  // at rest from the start
  scene.simulation.until_rest = {true, 1e-12, 20};
  const PhyxelSet set = sample_scene(scene);
  auto solver = make_cpu_solver(set, scene.simulation.gravity, 1);
  RunOptions options;
  options.steps = 1000;
  ASSERT_TRUE(run_simulation(scene, set, *solver, options).stopped_at_rest);
  auto view_solver = make_cpu_solver(set, scene.simulation.gravity, 1);
  ViewerSimulation view(scene, set, *view_solver, {});
  view.advance(300);
  EXPECT_EQ(view.step(), 300);
  EXPECT_TRUE(view.halted().empty());
}

}  // namespace
}  // namespace phyxel::render
