// The sever beside the stress pass (GpuSolverOptions::sever_beside_stress) where that pass has
// not run when the sever waits for it, as on a driver that ran the sever first: the wait is
// bounded, and the advance throws a VulkanError naming the device and the switch that turns the
// sever beside off ($PHYXEL_SEVER_BESIDE_STRESS=0), with which the same run cuts without error.
// (The same bits as the sever in its own pass: cutting_test.cpp.)
#include <chrono>
#include <cstdio>
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

TEST_F(GpuSolverTest, ASeverBesideAStressPassThatDidNotRunThrowsAClearError) {
  const Scene scene = crossed_beam();
  const PhyxelSet set = sample_scene(scene);
  GpuSolverOptions first;  // lavapipe runs dispatches in order: the epoch is never there
  first.sever_before_stress = true;
  {
    GpuSolver gpu(ctx(), set, scene.simulation.gravity, first);
    const auto start = std::chrono::steady_clock::now();
    try {
      advance_once(gpu, scene);
      ADD_FAILURE() << "the advance returned without an error";
    } catch (const VulkanError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(ctx().info().name + ": "), std::string::npos) << what;
      EXPECT_NE(what.find("found that pass not run"), std::string::npos) << what;
      EXPECT_NE(what.find("PHYXEL_SEVER_BESIDE_STRESS=0"), std::string::npos) << what;
    }
    std::printf("[ sever    ] the advance that threw took %.2f s\n",
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  {  // the switch: the sever in its own pass, no error, pairs cut
    const ScopedEnv off("PHYXEL_SEVER_BESIDE_STRESS", "0");
    GpuSolver gpu(ctx(), set, scene.simulation.gravity, first);
    EXPECT_NO_THROW(advance_once(gpu, scene));
    EXPECT_GT(gpu.severed_since(0).size(), 10u);
  }
  const ScopedEnv bad("PHYXEL_SEVER_BESIDE_STRESS", "off");
  EXPECT_THROW(GpuSolver(ctx(), set, scene.simulation.gravity), VulkanError);
}

}  // namespace
}  // namespace phyxel::gpu::test
