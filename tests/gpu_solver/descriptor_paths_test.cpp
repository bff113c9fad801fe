// The solver's dispatches bound through the Recorder's cached descriptor sets
// (ContextOptions::descriptor_cache) against pushed descriptors and a set written per dispatch:
// the same bits in the state, the aspirator's force every step and the aspirated mass, over a
// run that tears and aspirates (contact rows at offsets, buffers grown as the contact needs).
#include <gtest/gtest.h>

#include <vector>

#include "engine/run/simulation.h"
#include "tests/cutting/cutting_fixtures.h"
#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

TEST_F(GpuSolverTest, DescriptorPathsGiveTheSameBits) {
  const Scene scene =
      parse_scene(phyxel::test::suction_block_json(1000, true, 10000), "block.json");
  const PhyxelSet set = sample_scene(scene);
  std::vector<AspirationRun> runs;
  // Cached; pushed (where the device has push descriptors); written per dispatch.
  for (const bool cache : {true, false, false}) {
    ContextOptions options = test_context_options();
    options.descriptor_cache = cache;
    options.push_descriptors = runs.size() < 2;
    GpuSolver gpu(make_context(options), set, Vec3::Zero());
    runs.push_back(run_aspirating(scene, set, gpu, 150));
  }
  const AspirationRun& cached = runs[0];
  ASSERT_TRUE(cached.result.aspirating);
  EXPECT_GT(cached.result.aspiration.removed_mass[0], 0);
  for (size_t k = 1; k < runs.size(); ++k) {
    SCOPED_TRACE(k);
    EXPECT_EQ(runs[k].result.aspiration.events, cached.result.aspiration.events);
    EXPECT_EQ(runs[k].result.aspiration.removed_mass, cached.result.aspiration.removed_mass);
    EXPECT_EQ(runs[k].state.displacement, cached.state.displacement);
    EXPECT_EQ(runs[k].state.velocity, cached.state.velocity);
    EXPECT_EQ(runs[k].forces, cached.forces);
  }
}

}  // namespace
}  // namespace phyxel::gpu::test
