// The sever beside the stress pass (GpuSolverOptions::sever_beside_stress, one dispatch of both)
// and the switch that turns it off ($PHYXEL_SEVER_BESIDE_STRESS=0): the same run cuts with the
// sever in a pass of its own; a malformed value is a VulkanError. (The same bits as the sever in
// its own pass: cutting_test.cpp.)
#include <string>

#include "engine/surgery/tool_track.h"
#include "tests/cutting/cutting_fixtures.h"
#include "tests/gpu_solver/gpu_solver_fixture.h"
#include "tests/support/scoped_env.h"

namespace phyxel::gpu::test {
namespace {

using phyxel::test::ScopedEnv;

constexpr int64_t kSubsteps = 32;

// The clamped beam without gravity and a scalpel crossing it in its first 20 substeps: its
// first cuts a few substeps into the advance, where the sever goes beside the stress pass.
Scene crossed_beam() {
  Scene scene = phyxel::test::clamped_beam();
  scene.simulation.gravity = Vec3::Zero();
  scene.tools.push_back(phyxel::test::crossing_scalpel(0.0209, -0.003, 0.016, 0.0, 0.002));
  return scene;
}

// One advance of kSubsteps with the scalpel along its path.
void advance_once(GpuSolver& gpu, const Scene& scene) {
  ToolTrack track(scene.tools, {});
  Tools& tools = *gpu.tools();
  tools.set_tools(contact_tools(scene.tools));
  tools.set_tool_motion(track.motions(0, kSubsteps, scene.simulation.dt));
  gpu.advance(kSubsteps, scene.simulation.dt);
}

TEST_F(GpuSolverTest, TheSwitchPutsTheSeverInAPassOfItsOwn) {
  const Scene scene = crossed_beam();
  const PhyxelSet set = sample_scene(scene);
  auto beside = [&](GpuSolver& gpu) {
    bool fused = false;
    for (const PassTime& t : gpu.profile(2, scene.simulation.dt))
      fused = fused || t.name == "stress+cut";
    return fused;
  };
  {
    GpuSolver gpu(ctx(), set, scene.simulation.gravity);
    advance_once(gpu, scene);
    EXPECT_GT(gpu.severed_since(0).size(), 10u);
    EXPECT_TRUE(beside(gpu));
  }
  {  // the switch: the sever in its own pass, pairs cut
    const ScopedEnv off("PHYXEL_SEVER_BESIDE_STRESS", "0");
    GpuSolver gpu(ctx(), set, scene.simulation.gravity);
    EXPECT_NO_THROW(advance_once(gpu, scene));
    EXPECT_GT(gpu.severed_since(0).size(), 10u);
    EXPECT_FALSE(beside(gpu));
  }
  const ScopedEnv bad("PHYXEL_SEVER_BESIDE_STRESS", "off");
  EXPECT_THROW(GpuSolver(ctx(), set, scene.simulation.gravity), VulkanError);
}

}  // namespace
}  // namespace phyxel::gpu::test
