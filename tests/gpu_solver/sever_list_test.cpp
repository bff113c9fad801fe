// tool_sever over the cutting blades' own candidates (tool_broad_phase's second list, where no
// blade keeps sides): each chunk's count is contact_candidates' over blade_swept_bounds with
// the broad phase's margin, none while the scalpel is parked away (no workgroup) and fewer
// than all the candidates while it cuts far from the jaws; the pairs severed are the CPU's
// (which runs over all the candidates).
#include <algorithm>
#include <cstdio>
#include <numeric>
#include <set>
#include <utility>

#include "engine/surgery/tool_track.h"
#include "tests/cutting/cutting_fixtures.h"
#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

constexpr int64_t kChunk = 20;
constexpr int64_t kSteps = 200;

// The clamped beam without gravity; a scalpel parked 2 cm above it, that comes down, crosses
// it at x = 9 mm and goes back up, parked again for the last chunk; jaws on its free end.
Scene parked_cut_and_jaws() {
  Scene scene = phyxel::test::clamped_beam(5e4, 5);
  scene.simulation.gravity = Vec3::Zero();
  ToolDesc blade = phyxel::test::crossing_scalpel(0.009, -0.003, 0.016, 0.0, 0.002);
  blade.path = {{0.0, Vec3(0.009, -0.003, 0.03), Vec3::UnitZ()},
                {0.002, Vec3(0.009, -0.003, 0.03), Vec3::UnitZ()},
                {0.008, Vec3(0.009, -0.003, -0.003), Vec3::UnitZ()},
                {0.016, Vec3(0.009, 0.013, -0.003), Vec3::UnitZ()},
                {0.0175, Vec3(0.009, 0.013, 0.03), Vec3::UnitZ()}};
  scene.tools.push_back(blade);
  ToolDesc jaws;
  jaws.name = "jaws";
  jaws.type = ToolDesc::Type::Grasper;
  jaws.shape.radius = 0.0005;
  jaws.grasp.reach = 0.003;
  jaws.grasp.from = 0.0002;
  jaws.path = {{0.0, Vec3(0.039, 0.005, 0.005), Vec3::UnitZ()},
               {0.003, Vec3(0.039, 0.005, 0.005), Vec3::UnitZ()},
               {0.02, Vec3(0.040, 0.005, 0.005), Vec3::UnitZ()}};
  scene.tools.push_back(jaws);
  return scene;
}

// The broad phase's candidates within `bounds` for a chunk starting at state `now`
// (contact_candidates with the GPU's margin: CpuSolver::find_candidates').
size_t expected_candidates(const PhyxelSet& set, const std::vector<ContactTool>& tools,
                           const std::vector<ToolMotion>& motion, const PointState& now, double dt,
                           const Bounds& bounds) {
  std::vector<uint32_t> list(set.size());
  std::iota(list.begin(), list.end(), 0u);
  double max_v = 0;
  for (const Vec3& v : now.velocity) max_v = std::max(max_v, v.norm());
  const double spacing = set.objects[0].spacing, support = set.objects[0].support_radius;
  const double duration = dt * double(motion.size() / tools.size());
  const double margin = contact_margin(cut_candidate_reach(tools, spacing, support), max_v,
                                       tool_speed(tools, motion, dt), duration);
  return contact_candidates<double>(list, set.flags, set.rest, now.displacement, bounds, margin)
      .size();
}

TEST_F(GpuSolverTest, TheSeverRunsOverTheBladesOwnCandidatesOnly) {
  const Scene scene = parked_cut_and_jaws();
  const PhyxelSet set = sample_scene(scene);
  const double dt = scene.simulation.dt;
  const std::vector<ContactTool> tools = contact_tools(scene.tools);
  auto cpu = make_cpu_solver(set, scene.simulation.gravity, 1);
  GpuSolver gpu(ctx(), set, scene.simulation.gravity);
  ToolTrack track(scene.tools, {});
  for (Solver* s : {static_cast<Solver*>(cpu.get()), static_cast<Solver*>(&gpu)})
    s->tools()->set_tools(tools);
  size_t parked = 0, fewer = 0;
  for (int64_t s = 0; s < kSteps; s += kChunk) {
    const std::vector<ToolMotion> motion = track.motions(s, kChunk, dt);
    const PointState now = gpu.read_state(false);
    const size_t all =
        expected_candidates(set, tools, motion, now, dt, swept_bounds(tools, motion));
    const size_t own =
        expected_candidates(set, tools, motion, now, dt, blade_swept_bounds(tools, motion));
    for (Solver* solver : {static_cast<Solver*>(cpu.get()), static_cast<Solver*>(&gpu)}) {
      solver->tools()->set_tool_motion(motion);
      solver->advance(kChunk, dt);
    }
    EXPECT_EQ(gpu.contact_candidates(), all) << "chunk at step " << s;
    EXPECT_EQ(gpu.sever_candidates(), own) << "chunk at step " << s;
    std::printf("[ sever    ] chunk at step %3lld: %zu candidates, %zu the blade's\n",
                static_cast<long long>(s), gpu.contact_candidates(), gpu.sever_candidates());
    parked += all > 0 && gpu.sever_candidates() == 0 ? 1 : 0;
    fewer += gpu.sever_candidates() > 0 && gpu.sever_candidates() < all ? 1 : 0;
  }
  EXPECT_GE(parked, 2u);  // the first and the last chunk
  EXPECT_GE(fewer, 1u);
  const std::vector<SeveredPair> c = cpu->cutting()->severed_since(0);
  const std::vector<SeveredPair> g = gpu.severed_since(0);
  ASSERT_GT(c.size(), 50u);
  std::set<std::pair<uint32_t, uint32_t>> cs, gs;
  for (const SeveredPair& p : c) cs.insert({p.i, p.j});
  for (const SeveredPair& p : g) gs.insert({p.i, p.j});
  EXPECT_EQ(gs, cs);
  EXPECT_EQ(gpu.pair_alive(), cpu->cutting()->pair_alive());
  EXPECT_GT(gpu.held_phyxels(1).size(), 4u);
  const std::vector<Vec3> cu = cpu->read_state(false).displacement;
  EXPECT_LT(max_difference(cu, gpu.read_state(false).displacement),
            1e-4 * std::max(max_norm(cu), 1e-6));
}

}  // namespace
}  // namespace phyxel::gpu::test
