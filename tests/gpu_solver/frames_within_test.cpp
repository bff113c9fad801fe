// Frames inside the GPU solver's advances (RunOptions::frames_within_advance,
// Solver::advance_paused): an aspirating run with path tools draws its frames at the same steps,
// from the same u and with the tools at the same poses as a run whose frames end the advances,
// in fewer advances, and aspirates the same phyxels to the same bits as a run without frames.
// An advance's submissions grow from kFirstSubmitSteps, so the GPU starts early.
#include <gtest/gtest.h>

#include "engine/run/run_schedule.h"
#include "engine/run/simulation.h"
#include "tests/cutting/cutting_fixtures.h"
#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

struct FramedRun {
  std::vector<int64_t> frame_steps;
  std::vector<std::vector<layout::vec4>> shown;   // u the frame would draw, per frame
  std::vector<std::vector<Vec3>> tool_positions;  // per frame
  std::vector<uint32_t> removed;
  std::vector<Vec3> u, v;
  int64_t advances = 0;
};

FramedRun framed_run(Context& ctx, const Scene& scene, const PhyxelSet& set, int64_t frame_every,
                     bool within) {
  GpuSolver gpu(ctx, set, Vec3::Zero());
  RunOptions options;
  options.steps = 300;
  FramedRun out;
  std::vector<Vec3> tools(scene.tools.size());
  options.on_tool_step = [&](int64_t, double, const std::vector<ToolStepRecord>& records) {
    for (size_t k = 0; k < records.size(); ++k) tools[k] = records[k].pose.position;
  };
  if (frame_every > 0) {
    options.frame_every = frame_every;
    options.frames_within_advance = within;
    options.on_frame_tool_poses = [&](const std::vector<ToolPose>& poses) {
      for (size_t k = 0; k < poses.size(); ++k) tools[k] = poses[k].position;
    };
    options.on_frame = [&](int64_t step, Solver&) {
      // What the renderer reads (buffers()), read as a frame's pass would: on the queue, after
      // the work submitted so far.
      const SolverBuffers b = gpu.buffers();
      out.frame_steps.push_back(step);
      out.shown.push_back(download<layout::vec4>(ctx, *b.displacement, b.count));
      out.tool_positions.push_back(tools);
    };
  }
  options.on_aspiration = [&](const AspirationEvent& e) {
    out.removed.insert(out.removed.end(), e.removed.begin(), e.removed.end());
  };
  const RunResult r = run_simulation(scene, set, gpu, options);
  EXPECT_TRUE(r.aspirating);
  const PointState s = gpu.read_state(false);
  out.u = s.displacement;
  out.v = s.velocity;
  out.advances = gpu.advance_host_times().advances;
  return out;
}

TEST_F(GpuSolverTest, FramesInsideTheAdvancesDrawWhatSplitAdvancesDrawAndChangeNothing) {
  const Scene scene =
      parse_scene(phyxel::test::suction_block_json(1000, true, 10000), "block.json");
  const PhyxelSet set = sample_scene(scene);
  const FramedRun bare = framed_run(ctx(), scene, set, 0, false);
  ASSERT_FALSE(bare.removed.empty()) << "the run must aspirate";
  const int64_t every = 7;  // neither divides the tool chunk nor is a multiple of it
  const FramedRun split = framed_run(ctx(), scene, set, every, false);
  const FramedRun within = framed_run(ctx(), scene, set, every, true);
  // Without frames an advance is a tool chunk (the checks fall on their lines); frames inside
  // end none, where split ones add one per frame.
  const TimeStepPlan plan = plan_time_step(scene, set);
  const int64_t chunk =
      tool_chunk_steps(scene, RunOptions{}, set.size(), plan.substeps, plan.dt_requested);
  EXPECT_EQ(bare.advances, (300 + chunk - 1) / chunk);
  EXPECT_EQ(within.advances, bare.advances);
  EXPECT_GT(split.advances, bare.advances + 20);  // 42 frames, some on a line already
  ASSERT_EQ(within.frame_steps, split.frame_steps);
  ASSERT_GT(within.frame_steps.size(), 40u);
  for (size_t f = 0; f < within.frame_steps.size(); ++f) {
    SCOPED_TRACE(within.frame_steps[f]);
    ASSERT_EQ(within.tool_positions[f], split.tool_positions[f]);
    ASSERT_EQ(within.shown[f].size(), split.shown[f].size());
    for (size_t i = 0; i < within.shown[f].size(); ++i) {
      const layout::vec4 &a = within.shown[f][i], &b = split.shown[f][i];
      ASSERT_TRUE(a.x == b.x && a.y == b.y && a.z == b.z) << "phyxel " << i;
    }
  }
  for (const FramedRun* r : {&split, &within}) {
    EXPECT_EQ(r->removed, bare.removed);
    ASSERT_EQ(r->u.size(), bare.u.size());
    for (size_t i = 0; i < bare.u.size(); ++i) {
      ASSERT_EQ(r->u[i], bare.u[i]) << "phyxel " << i;
      ASSERT_EQ(r->v[i], bare.v[i]) << "phyxel " << i;
    }
  }
}

TEST_F(GpuSolverTest, AnAdvanceIsSubmittedInPiecesThatGrowFromTheFirstEightSubsteps) {
  const Scene scene = two_material_scene();
  const PhyxelSet set = sample_scene(scene);
  GpuSolver gpu(ctx(), set, scene.simulation.gravity);
  gpu.advance(64, plan_time_step(scene, set).dt_stable);
  // 8, 8, 8, 12, 18 and the last 10; the last left running (nothing to read back).
  EXPECT_EQ(GpuSolver::submit_steps(0), 8);
  EXPECT_EQ(GpuSolver::submit_steps(36), 18);
  EXPECT_EQ(GpuSolver::submit_steps(4096), GpuSolver::kStepsPerSubmit);
  EXPECT_EQ(gpu.advance_host_times().advances, 1);
  EXPECT_EQ(gpu.advance_host_times().submissions, 6);
  EXPECT_EQ(gpu.advance_host_times().waits, 5);
  EXPECT_TRUE(gpu.advance_in_flight());
}

TEST_F(GpuSolverTest, PausesMustAscendInsideTheAdvance) {
  const Scene scene = two_material_scene();
  const PhyxelSet set = sample_scene(scene);
  GpuSolver gpu(ctx(), set, scene.simulation.gravity);
  const double dt = plan_time_step(scene, set).dt_stable;
  std::vector<int64_t> seen;
  gpu.advance_paused(20, dt, {3, 11}, [&](int64_t k) { seen.push_back(k); });
  EXPECT_EQ(seen, (std::vector<int64_t>{3, 11}));
  for (const std::vector<int64_t>& bad :
       {std::vector<int64_t>{0}, std::vector<int64_t>{20}, std::vector<int64_t>{5, 5}})
    EXPECT_THROW(gpu.advance_paused(20, dt, bad, [](int64_t) {}), std::invalid_argument);
}

}  // namespace
}  // namespace phyxel::gpu::test
