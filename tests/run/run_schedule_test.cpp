// The run loop's schedule (engine/run/run_schedule.h): where tools move and no check decides
// rest or sleep, the checks fall on the tool chunks' grid, so they end no advance off it.
#include <gtest/gtest.h>

#include "engine/run/run_schedule.h"
#include "tests/physics/physics_fixtures.h"

namespace phyxel {
namespace {

TEST(RunSchedule, ChecksOfAToolSceneFallOnTheToolChunksGrid) {
  Scene scene =
      test::box_scene(Vec3(0, 0, 0), Vec3(0.01, 0.01, 0.01), 0.0025, test::tissue(1e5, 0.3, 50));
  RunOptions options;
  EXPECT_EQ(tool_chunk_steps(scene, options, 1), 0);
  EXPECT_EQ(check_interval(scene, options, false, 0), 100);
  ToolDesc probe;
  probe.name = "probe";
  probe.shape.radius = 0.003;
  probe.path = {{0, Vec3(0.005, 0.005, 0.0135), Vec3::UnitZ()}};
  scene.tools = {probe};
  EXPECT_EQ(tool_chunk_steps(scene, options, 1), 64);
  EXPECT_EQ(tool_chunk_steps(scene, options, 2), 32);
  EXPECT_EQ(tool_chunk_steps(scene, options, 100), 1);
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

}  // namespace
}  // namespace phyxel
