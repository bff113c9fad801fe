// `phyxel bench --surgery` end to end, short (CPU, a small scalpel scene at two K, tiny frames):
// the JSON has a row per scene and K with every figure the table prints. Timing never decides
// the test: only the output's shape and that its numbers are finite.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/physics/physics_fixtures.h"
#include "tests/support/support.h"

namespace phyxel {
namespace {

void expect_finite(const nlohmann::json& j, const char* key) {
  ASSERT_TRUE(j.contains(key)) << key << " in " << j.dump();
  EXPECT_TRUE(std::isfinite(j[key].get<double>())) << key;
}

TEST(BenchSurgery, WritesARowPerSceneAndRefinement) {
  const std::filesystem::path dir = test::test_output_dir("bench_surgery");
  const std::string command =
      std::string("timeout 600 ") + PHYXEL_BINARY_DIR +
      "/app/phyxel bench --surgery --device cpu " + "--scenes " + PHYXEL_SOURCE_DIR +
      "/scenes/scalpel_cut.json --refine 1,1.2 --steps 4 " +
      "--width 64 --height 48 --fps 1000 --bare-steps 2 --threads 1 --out " + dir.string() + " > " +
      (dir / "stdout.txt").string() + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0);
  const nlohmann::json j = test::read_json(dir / "surgery.json");
  ASSERT_EQ(j["surgery"].size(), 2u);
  for (size_t r = 0; r < 2; ++r) {
    const nlohmann::json& row = j["surgery"][r];
    EXPECT_EQ(row["refine"].get<double>(), r == 0 ? 1.0 : 1.2);
    for (const char* key : {"surgery_substep_us", "box_substep_us", "surgery_over_box"})
      expect_finite(row, key);
    for (const char* run : {"bare", "frames"}) {
      const nlohmann::json& w = row[run];
      for (const char* key : {"substeps_per_second", "real_time_factor", "wall_seconds"})
        expect_finite(w, key);
      EXPECT_EQ(w["steps"].get<int>(), 4);
      for (const char* part : {"advance", "checks", "callbacks", "pacing", "outputs"})
        expect_finite(w["host_seconds"], part);
      EXPECT_TRUE(w["finite"].get<bool>());
      EXPECT_TRUE(w["outcome"].is_object());
    }
    EXPECT_TRUE(row["bare"]["gpu_pass_us"].is_object());  // empty on the CPU
    EXPECT_GE(row["frames"]["frame_every_steps"].get<int>(), 1);
    // The frame writer's parts: a frame at the end at least.
    const nlohmann::json& writer = row["frames"]["frame_host_seconds"];
    EXPECT_GE(writer["frames"].get<int>(), 1);
    for (const char* part : {"wait", "cuts", "aspiration", "video", "submit"})
      expect_finite(writer, part);
  }
  EXPECT_GT(j["surgery"][1]["phyxels"].get<int>(), j["surgery"][0]["phyxels"].get<int>());
}

TEST(BenchSurgery, BadRefinementIsAUsageError) {
  const std::string command = std::string(PHYXEL_BINARY_DIR) +
                              "/app/phyxel bench --surgery --refine 1,0.5 > /dev/null 2>&1";
  const int status = std::system(command.c_str());
  EXPECT_EQ(WEXITSTATUS(status), 2);
}

}  // namespace
}  // namespace phyxel
