// GpuSolver::advance returns while its last command buffer runs where the host has nothing left
// to do for it (compute/gpu_solver.h): every other call waits for that submission first, so a
// solver called straight after its advances gives the bits of one that finished each advance,
// and one with tools or tearing finishes its advances itself.
#include <cmath>

#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

// The bits of everything a run reads from a solver after each of a series of advances: each
// advance is followed by one of the solver's calls (the queries, a load change, set_state).
struct Readings {
  std::vector<double> numbers;
  std::vector<Vec3> vectors;
  std::vector<bool> in_flight;  // after each advance
};

Readings advance_and_read(GpuSolver& gpu, const PhyxelSet& set, double dt, bool finish) {
  Readings r;
  auto step = [&](int64_t steps) {
    gpu.advance(steps, dt);
    r.in_flight.push_back(gpu.advance_in_flight());
    if (finish) gpu.finish();
  };
  step(2 * GpuSolver::kStepsPerSubmit + 44);  // three submissions: two in flight at a time
  step(30);  // advances back to back: each waits for the last one's submission
  step(20);
  const Energies e = gpu.energies();
  r.numbers.insert(r.numbers.end(), {e.kinetic, e.strain, e.potential});
  step(50);
  r.numbers.push_back(double(gpu.first_non_finite()));
  step(50);
  const auto [u_max, v_max] = gpu.max_norms();
  r.numbers.insert(r.numbers.end(), {u_max, v_max});
  step(50);
  for (const ObjectMotion& m : gpu.object_motion(set))
    r.numbers.insert(r.numbers.end(), {m.kinetic, m.max_speed});
  step(50);
  gpu.set_external_forces(std::vector<Vec3>(set.size(), Vec3(0, 0, 1e-4)));
  step(50);
  gpu.set_pass_selection(false);
  step(50);
  const PointState s = gpu.read_state(false);
  gpu.set_state(s.displacement, s.velocity);
  step(50);
  const std::vector<Vec3> f = gpu.forces();
  r.vectors.insert(r.vectors.end(), f.begin(), f.end());
  step(50);
  const PointState last = gpu.read_state(true);
  r.vectors.insert(r.vectors.end(), last.displacement.begin(), last.displacement.end());
  r.vectors.insert(r.vectors.end(), last.velocity.begin(), last.velocity.end());
  r.numbers.insert(r.numbers.end(), last.von_mises.begin(), last.von_mises.end());
  return r;
}

TEST_F(GpuSolverTest, CallsAfterAnAdvanceInFlightReadWhatAFinishedAdvanceLeft) {
  const Scene scene = two_material_scene();
  const PhyxelSet set = sample_scene(scene, SamplingOptions{false});
  const double dt = plan_time_step(scene, set).dt_used;
  GpuSolver eager(ctx(), set, scene.simulation.gravity);
  GpuSolver waited(ctx(), set, scene.simulation.gravity);
  const Readings a = advance_and_read(eager, set, dt, false);
  const Readings b = advance_and_read(waited, set, dt, true);
  // Every advance of the tool-less solver returned with its last submission running.
  EXPECT_EQ(a.in_flight, std::vector<bool>(a.in_flight.size(), true));
  EXPECT_FALSE(eager.advance_in_flight());  // read_state waited for it
  ASSERT_EQ(a.numbers.size(), b.numbers.size());
  for (size_t k = 0; k < a.numbers.size(); ++k) {
    ASSERT_TRUE(std::isfinite(a.numbers[k])) << k;
    EXPECT_EQ(a.numbers[k], b.numbers[k]) << k;  // the same bits
  }
  EXPECT_EQ(a.vectors, b.vectors);
  EXPECT_GT(max_norm(a.vectors), 0.0);
  // A solver destroyed with an advance in flight waits for it (the validation layer reports a
  // command buffer freed while in use).
  GpuSolver dropped(ctx(), set, scene.simulation.gravity);
  dropped.advance(GpuSolver::kStepsPerSubmit + 1, dt);
  EXPECT_TRUE(dropped.advance_in_flight());
}

TEST_F(GpuSolverTest, AdvancesWithWorkLeftForTheHostFinishThemselves) {
  const Scene scene = two_material_scene();
  const PhyxelSet set = sample_scene(scene, SamplingOptions{false});
  const double dt = plan_time_step(scene, set).dt_used;
  {  // A tool: its samples come back at the end of the advance.
    GpuSolver gpu(ctx(), set, scene.simulation.gravity);
    ContactTool probe;
    probe.shape = {ToolShape::Type::Sphere, 0.002, 0.0};
    gpu.set_tools({probe});
    const ToolPose far{Vec3(1, 1, 1), Vec3::UnitZ()};
    gpu.set_tool_motion(std::vector<ToolMotion>(10, ToolMotion{far, far}));
    gpu.advance(10, dt);
    EXPECT_FALSE(gpu.advance_in_flight());
    EXPECT_EQ(gpu.tool_samples().size(), 10u);
  }
  {  // Tearing: the pairs torn come back at the end of the advance.
    GpuSolver gpu(ctx(), set, scene.simulation.gravity);
    gpu.set_tearing(true);
    gpu.advance(10, dt);
    EXPECT_FALSE(gpu.advance_in_flight());
  }
}

// prefetch_checks: the advance records the checks at its end; first_non_finite and max_norms
// after it give the bits of their own submissions, until a call that may change the state.
TEST_F(GpuSolverTest, PrefetchedChecksGiveTheBitsOfTheirOwnSubmissions) {
  const Scene scene = two_material_scene();
  const PhyxelSet set = sample_scene(scene, SamplingOptions{false});
  const double dt = plan_time_step(scene, set).dt_used;
  GpuSolver a(ctx(), set, scene.simulation.gravity);
  GpuSolver b(ctx(), set, scene.simulation.gravity);
  auto same = [&] {
    EXPECT_EQ(a.first_non_finite(), b.first_non_finite());
    const auto [ua, va] = a.max_norms();
    const auto [ub, vb] = b.max_norms();
    EXPECT_EQ(ua, ub);
    EXPECT_EQ(va, vb);
    EXPECT_GT(va, 0.0);
  };
  a.prefetch_checks();
  a.advance(30, dt);  // left in flight (no tools): the reads wait for it
  b.advance(30, dt);
  EXPECT_TRUE(a.checks_prefetched());
  EXPECT_FALSE(b.checks_prefetched());
  same();
  EXPECT_TRUE(a.checks_prefetched());  // read again, the same
  same();
  const Bounds box{Vec3::Constant(-1), Vec3::Constant(1)};  // every phyxel
  EXPECT_EQ(a.read_near(set, box).ids, b.read_near(set, box).ids);
  EXPECT_EQ(a.read_displacements({0, 7}), b.read_displacements({0, 7}));
  EXPECT_TRUE(a.checks_prefetched());  // reads keep them

  // A call that may change the state drops them.
  const std::vector<Vec3> loads(set.size(), Vec3(0, 0, 1e-4));
  a.prefetch_checks();
  a.advance(20, dt);
  b.advance(20, dt);
  a.set_external_forces(loads);
  b.set_external_forces(loads);
  EXPECT_FALSE(a.checks_prefetched());
  same();

  // Asked for one advance only.
  a.prefetch_checks();
  a.advance(3, dt);
  a.advance(3, dt);
  b.advance(6, dt);
  EXPECT_FALSE(a.checks_prefetched());
  same();

  // A non-finite velocity: both name the same phyxel.
  PointState s = a.read_state(false);
  s.velocity[11] = Vec3(std::nan(""), 0, 0);
  a.set_state(s.displacement, s.velocity);
  b.set_state(s.displacement, s.velocity);
  a.prefetch_checks();
  a.advance(1, dt);
  b.advance(1, dt);
  EXPECT_TRUE(a.checks_prefetched());
  EXPECT_GE(a.first_non_finite(), 0);
  EXPECT_EQ(a.first_non_finite(), b.first_non_finite());
}

}  // namespace
}  // namespace phyxel::gpu::test
