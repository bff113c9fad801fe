// Keep one side at a separation on the GPU against the CPU (engine/solver/cutting.h,
// held_pair_severed; tool_sever.comp's held_since_separation): the pairs a blade's edge holds
// below its threshold are marked alike, its separations sever the same pairs, and a checkpoint's
// marks and sides put back sever a pair held since the last separation where its phyxels are
// kept apart.
#include <algorithm>
#include <cstdio>
#include <set>
#include <tuple>
#include <vector>

#include "engine/surgery/tool_track.h"
#include "tests/cutting/cutting_fixtures.h"
#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

using MarkSet = std::set<std::tuple<uint32_t, uint32_t, uint32_t>>;

MarkSet mark_set(const std::vector<HeldMark>& marks) {
  MarkSet s;
  for (const HeldMark& m : marks) s.insert({m.i, m.j, m.bits});
  return s;
}

std::set<std::pair<uint32_t, uint32_t>> severed_set(Solver& solver) {
  std::set<std::pair<uint32_t, uint32_t>> s;
  for (const SeveredPair& p : solver.cutting()->severed_since(0)) s.insert({p.i, p.j});
  return s;
}

// A scalpel_cut-like block (2 mm, 5 kPa, fixed below 1.5 mm) from y = `y0` and a blade (body
// 0.4 mm) at `threshold` moved along +x, its tip at (x, `y`, `tip`).
Scene marked_block(double threshold, double y0, double y, double tip, double from, double to) {
  Scene scene = phyxel::test::box_scene(Vec3(-0.008, y0, 0), Vec3(0.008, y0 + 0.008, 0.008), 0.002,
                                        phyxel::test::tissue(5000, 0.45, 20));
  scene.objects[0].fixed.push_back(phyxel::test::box_shape(Vec3(-1, -1, -1), Vec3(1, 1, 0.0015)));
  scene.simulation.dt = 2.4e-4;
  ToolDesc blade = phyxel::test::crossing_scalpel(0, tip, 0.02, 0.0, 0.1, threshold);
  blade.shape.radius = 0.0004;
  blade.path = {{0.0, Vec3(from, y, tip), Vec3::UnitZ()}, {0.1, Vec3(to, y, tip), Vec3::UnitZ()}};
  blade.blade.edge = Vec3::UnitX();
  scene.tools.push_back(blade);
  return scene;
}

// The block and blade of ABladeKeepsEachPhyxelOnOneSideAsTheCpuDoes (the lattice 20 um off the
// blade's plane, out of the float-double tie band), both solvers run in chunks of 50 steps:
// after each chunk the same marks and severed pairs.
TEST_F(GpuSolverTest, TheEdgesHeldMarksAndTheirSeparationsMatchTheCpu) {
  const Scene scene = marked_block(0.02, -0.00398, 0, 0.003, -0.012, 0.004);
  const PhyxelSet set = sample_scene(scene);
  auto cpu = make_cpu_solver(set, scene.simulation.gravity, 1);
  GpuSolver gpu(ctx(), set, scene.simulation.gravity);
  ToolTrack track_cpu(scene.tools, {}), track_gpu(scene.tools, {});  // each keeps its poses
  for (Solver* s : {cpu.get(), static_cast<Solver*>(&gpu)})
    s->tools()->set_tools(contact_tools(scene.tools));
  size_t most_marks = 0;
  for (int64_t step = 0; step < 300; step += 50) {
    for (Solver* s : {cpu.get(), static_cast<Solver*>(&gpu)}) {
      ToolTrack& track = s == cpu.get() ? track_cpu : track_gpu;
      s->tools()->set_tool_motion(track.motions(step, 50, scene.simulation.dt));
      s->advance(50, scene.simulation.dt);
    }
    const MarkSet c = mark_set(cpu->cutting()->held_marks());
    EXPECT_EQ(mark_set(gpu.held_marks()), c) << "after step " << step + 50;
    EXPECT_EQ(severed_set(gpu), severed_set(*cpu)) << "after step " << step + 50;
    most_marks = std::max(most_marks, c.size());
  }
  std::printf("[ marks    ] up to %zu marked slots, %zu pairs severed\n", most_marks,
              severed_set(*cpu).size());
  EXPECT_GT(most_marks, 10u);
  EXPECT_GT(severed_set(*cpu).size(), 60u);
}

// The pair (-4, 2, 4) - (-4, 0, 4) mm crosses the blade's plane (y = 1 mm) below its tip
// (z = 6 mm): no crossing rule takes it. Marked (as a checkpoint puts it back) with its phyxels
// kept apart, the first substep's separation (threshold 1e-9 N) severs it on both solvers, at
// t 0.5, and clears the marks.
TEST_F(GpuSolverTest, APairHeldSinceTheLastSeparationIsSeveredAsOnTheCpu) {
  const Scene scene = marked_block(1e-9, -0.004, 0.001, 0.006, -0.004, 0.006);
  const PhyxelSet set = sample_scene(scene);
  uint32_t i = 0, j = 0;
  for (uint32_t k = 0; k < set.size(); ++k) {
    if ((set.rest[k] - Vec3(-0.004, 0.002, 0.004)).norm() < 1e-9) i = k;
    if ((set.rest[k] - Vec3(-0.004, 0, 0.004)).norm() < 1e-9) j = k;
  }
  ASSERT_NE(i, j);
  auto cpu = make_cpu_solver(set, scene.simulation.gravity, 1);
  GpuSolver gpu(ctx(), set, scene.simulation.gravity);
  const uint32_t normal = pack_side_normal(Vec3::UnitY());
  const std::vector<HeldMark> marks = {{i, j, 1u}, {j, i, 1u}};
  for (Solver* s : {cpu.get(), static_cast<Solver*>(&gpu)}) {
    ToolTrack track(scene.tools, {});
    s->tools()->set_tools(contact_tools(scene.tools));
    s->cutting()->restore_blade_sides({{{i, kSidePlus, normal}, {j, kSideMinus, normal}}});
    s->cutting()->restore_held_marks(marks);
    EXPECT_EQ(mark_set(s->cutting()->held_marks()), mark_set(marks));
    s->tools()->set_tool_motion(track.motions(0, 1, scene.simulation.dt));
    s->advance(1, scene.simulation.dt);
    const auto cut = severed_set(*s);
    EXPECT_TRUE(cut.count({std::min(i, j), std::max(i, j)})) << s->device();
    EXPECT_TRUE(mark_set(s->cutting()->held_marks()).empty()) << s->device();
  }
  EXPECT_EQ(severed_set(gpu), severed_set(*cpu));
}

}  // namespace
}  // namespace phyxel::gpu::test
