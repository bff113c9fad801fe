// The run loop's schedule (engine/run/run_schedule.h): where tools move and no check decides
// rest or sleep, the checks fall on the tool chunks' grid, so they end no advance off it.
#include <gtest/gtest.h>

#include "engine/run/run_schedule.h"
#include "tests/physics/physics_fixtures.h"

namespace phyxel {
namespace {

constexpr size_t kLarge = 200000;  // phyxels: past kSmallBodyPhyxels

TEST(RunSchedule, ChecksOfAToolSceneFallOnTheToolChunksGrid) {
  Scene scene =
      test::box_scene(Vec3(0, 0, 0), Vec3(0.01, 0.01, 0.01), 0.0025, test::tissue(1e5, 0.3, 50));
  RunOptions options;
  EXPECT_EQ(tool_chunk_steps(scene, options, kLarge, 1, 1e-4), 0);
  EXPECT_EQ(check_interval(scene, options, false, 0), 100);
  ToolDesc probe;
  probe.name = "probe";
  probe.shape.radius = 0.003;
  probe.path = {{0, Vec3(0.005, 0.005, 0.0135), Vec3::UnitZ()}};
  scene.tools = {probe};
  EXPECT_EQ(tool_chunk_steps(scene, options, kLarge, 1, 1e-4), 64);
  EXPECT_EQ(tool_chunk_steps(scene, options, kLarge, 2, 1e-4), 32);
  EXPECT_EQ(tool_chunk_steps(scene, options, kLarge, 100, 1e-4), 1);
  // The multiple of the chunk nearest 100 steps.
  EXPECT_EQ(check_interval(scene, options, false, 64), 128);
  EXPECT_EQ(check_interval(scene, options, false, 32), 96);
  EXPECT_EQ(check_interval(scene, options, false, 21), 105);
  EXPECT_EQ(check_interval(scene, options, false, 1), 100);
  EXPECT_EQ(check_interval(scene, options, false, 300), 300);
  // Where the checks decide sleep or rest, their own intervals, as without tools.
  scene.simulation.sleep.for_steps = 300;
  EXPECT_EQ(check_interval(scene, options, true, 64), 30);
  scene.simulation.until_rest.enabled = true;
  scene.simulation.until_rest.for_steps = 500;
  EXPECT_EQ(check_interval(scene, options, false, 64), 50);
  options.check_every = 7;
  EXPECT_EQ(check_interval(scene, options, false, 64), 7);
}

// A body of up to 100 000 phyxels advances 128 substeps at a time with tools, a larger one
// 64, unless RunOptions::tool_chunk_substeps says.
TEST(RunSchedule, SmallBodiesAdvanceLongerToolChunks) {
  Scene scene =
      test::box_scene(Vec3(0, 0, 0), Vec3(0.01, 0.01, 0.01), 0.0025, test::tissue(1e5, 0.3, 50));
  ToolDesc probe;
  probe.name = "probe";
  probe.shape.radius = 0.003;
  probe.path = {{0, Vec3(0.005, 0.005, 0.0135), Vec3::UnitZ()}};
  scene.tools = {probe};
  RunOptions options;
  EXPECT_EQ(tool_chunk_substeps(options, 10579), 128);
  EXPECT_EQ(tool_chunk_substeps(options, 100000), 128);
  EXPECT_EQ(tool_chunk_substeps(options, 100001), 64);
  EXPECT_EQ(tool_chunk_steps(scene, options, 10579, 2, 1e-4), 64);
  EXPECT_EQ(tool_chunk_steps(scene, options, 165565, 2, 1e-4), 32);
  options.tool_chunk_substeps = 16;  // set: whatever the body
  EXPECT_EQ(tool_chunk_steps(scene, options, 10579, 2, 1e-4), 8);
  EXPECT_EQ(tool_chunk_steps(scene, options, 165565, 2, 1e-4), 8);
}

// An aspirator acts on the tool chunks' lines. Until 2026-11-27 a chunk was 64 substeps, so
// refining the tissue (more substeps per step) made it aspirate more often: every 10.2, 5.1 and
// 3.4 ms in the brain scene at --refine 1, 2 and 3, and that, not the spacing, made its healthy
// loss fall with K (docs/suction.md, "Resolution"). Now every suction.interval whatever the
// substeps, where tissue can tear.
TEST(RunSchedule, AnAspiratorActsEveryIntervalWhateverTheSubsteps) {
  Material brain = test::tissue(3e3, 0.45, 30);
  brain.tear_stress = 2500;
  Scene scene = test::box_scene(Vec3(0, 0, 0), Vec3(0.01, 0.01, 0.01), 0.002, brain);
  ToolDesc aspirator;
  aspirator.name = "aspirator";
  aspirator.type = ToolDesc::Type::Suction;
  aspirator.shape.radius = 0.0015;
  aspirator.suction.pressure = 25000;
  aspirator.suction.reach = 0.004;
  aspirator.path = {{0, Vec3(0.005, 0.005, 0.012), Vec3::UnitZ()}};
  scene.tools = {aspirator};
  const RunOptions options;
  const double step = 1.6e-4;  // the brain scene's
  const int64_t steps = int64_t(aspirator.suction.interval / step);
  for (const int64_t substeps : {1, 2, 3}) {  // 64, 32 and 21 steps on the old rule
    SCOPED_TRACE(substeps);
    EXPECT_EQ(tool_chunk_steps(scene, options, kLarge, substeps, step), steps);
  }
  // Finer than the interval where 64 substeps take less time.
  EXPECT_EQ(tool_chunk_steps(scene, options, kLarge, 4, step), 16);
  EXPECT_EQ(tool_chunk_steps(scene, options, kLarge, 8, step), 8);
  // An interval of a whole number of steps is that number, not one fewer.
  scene.tools[0].suction.interval = 5 * step;
  EXPECT_EQ(tool_chunk_steps(scene, options, kLarge, 1, step), 5);
  // Where nothing can tear, nothing is aspirated: the chunk is 64 substeps.
  scene.objects[0].material.tear_stress.reset();
  EXPECT_EQ(tool_chunk_steps(scene, options, kLarge, 1, step), 64);
}

}  // namespace
}  // namespace phyxel
