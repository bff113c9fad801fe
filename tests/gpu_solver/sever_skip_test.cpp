// No sever dispatch in a chunk with no candidate near a blade (GpuSolverOptions::sever_skip_idle:
// the broad phase's predicate under VK_EXT_conditional_rendering): a scalpel parked away from
// the beam while the jaws hold its end (candidates, none near the blade), then crossing it. The
// predicate is off while it is parked and on while it cuts, and the run gives the bits of the
// sever dispatched in every substep: the same severed pairs and t, pairs alive, u and samples.
#include <cstdio>
#include <optional>
#include <vector>

#include "engine/surgery/tool_track.h"
#include "tests/cutting/cutting_fixtures.h"
#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

constexpr int64_t kChunk = 16;
constexpr int64_t kSteps = 128;  // 8 chunks of 0.1 ms substeps

// The beam without gravity, its free end held by jaws that pull it; a blade without a
// threshold parked 3 cm off the beam for two chunks, brought to it in the third and crossing
// it in the others.
Scene parked_then_cutting() {
  Scene scene = phyxel::test::clamped_beam(5e4, 5);
  scene.simulation.gravity = Vec3::Zero();
  ToolDesc blade = phyxel::test::crossing_scalpel(0.021, -0.003, 0.016, 0.0048, 0.008);
  const Vec3 parked(0.021, -0.03, -0.003);
  blade.path.insert(blade.path.begin(),
                    {{0.0, parked, Vec3::UnitZ()}, {0.0032, parked, Vec3::UnitZ()}});
  scene.tools.push_back(blade);
  ToolDesc jaws;
  jaws.name = "jaws";
  jaws.type = ToolDesc::Type::Grasper;
  jaws.shape.radius = 0.0005;
  jaws.grasp.reach = 0.003;
  jaws.grasp.from = 0.0002;
  jaws.path = {{0.0, Vec3(0.039, 0.005, 0.005), Vec3::UnitZ()},
               {0.003, Vec3(0.039, 0.005, 0.005), Vec3::UnitZ()},
               {0.0128, Vec3(0.040, 0.005, 0.005), Vec3::UnitZ()}};
  scene.tools.push_back(jaws);
  return scene;
}

struct SkipRun {
  std::vector<SeveredPair> severed;
  std::vector<Vec3> u;
  std::vector<uint8_t> alive;
  std::vector<ToolContactSample> samples;
  std::vector<size_t> candidates;         // per chunk
  std::vector<std::optional<bool>> near;  // per chunk: the sever's predicate
};

SkipRun run(GpuSolver& gpu, const Scene& scene) {
  ToolTrack track(scene.tools, {});
  Tools& tools = *gpu.tools();
  tools.set_tools(contact_tools(scene.tools));
  const double dt = scene.simulation.dt;
  SkipRun out;
  for (int64_t s = 0; s < kSteps; s += kChunk) {
    tools.set_tool_motion(track.motions(s, kChunk, dt));
    gpu.advance(kChunk, dt);
    out.candidates.push_back(tools.contact_candidates());
    out.near.push_back(gpu.sever_near_blade());
    const std::vector<ToolContactSample> felt = tools.tool_samples();
    out.samples.insert(out.samples.end(), felt.begin(), felt.end());
  }
  out.severed = gpu.cutting()->severed_since(0);
  out.u = gpu.read_state(false).displacement;
  out.alive = gpu.cutting()->pair_alive();
  return out;
}

TEST_F(GpuSolverTest, NoSeverDispatchWhileNoBladeIsNearGivesTheSameBits) {
  const Scene scene = parked_then_cutting();
  const PhyxelSet set = sample_scene(scene);
  GpuSolverOptions always;
  always.sever_skip_idle = false;
  GpuSolver skipping(ctx(), set, scene.simulation.gravity);
  GpuSolver dispatching(ctx(), set, scene.simulation.gravity, always);
  const SkipRun a = run(skipping, scene);
  const SkipRun b = run(dispatching, scene);
  for (const std::optional<bool>& n : b.near) EXPECT_FALSE(n.has_value());
  if (ctx().conditional_rendering()) {
    ASSERT_EQ(a.near.size(), size_t{kSteps / kChunk});
    for (int64_t c = 0; c < kSteps / kChunk; ++c) {
      EXPECT_GT(a.candidates[c], 0u) << "chunk " << c;  // the jaws'
      ASSERT_TRUE(a.near[c].has_value());
      EXPECT_EQ(*a.near[c], c >= 2) << "chunk " << c;  // parked in the first two
    }
  } else {
    std::printf("[ skip     ] %s: no VK_EXT_conditional_rendering, the sever always runs\n",
                ctx().info().name.c_str());
  }
  EXPECT_GT(a.severed.size(), 20u);
  ASSERT_EQ(a.severed.size(), b.severed.size());
  for (size_t k = 0; k < a.severed.size(); ++k) {
    EXPECT_EQ(a.severed[k].i, b.severed[k].i) << k;
    EXPECT_EQ(a.severed[k].j, b.severed[k].j) << k;
    EXPECT_EQ(a.severed[k].t, b.severed[k].t) << k;
  }
  EXPECT_EQ(a.alive, b.alive);
  ASSERT_EQ(a.u.size(), b.u.size());
  for (size_t i = 0; i < a.u.size(); ++i) ASSERT_EQ(a.u[i], b.u[i]) << i;
  ASSERT_EQ(a.samples.size(), b.samples.size());
  for (size_t k = 0; k < a.samples.size(); ++k) {
    EXPECT_EQ(a.samples[k].force, b.samples[k].force) << k;
    EXPECT_EQ(a.samples[k].held, b.samples[k].held) << k;
  }
  EXPECT_GT(skipping.held_phyxels(1).size(), 4u);
  EXPECT_EQ(skipping.held_phyxels(1), dispatching.held_phyxels(1));
  std::printf("[ skip     ] %zu pairs severed, the same bits\n", a.severed.size());
}

}  // namespace
}  // namespace phyxel::gpu::test
