// `phyxel bench --tearing` end to end, short (CPU, one small box): the JSON has its row with
// finite values, and the box with tear_stress tore where the probe ploughed through it. Timing
// never decides the test.
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

TEST(BenchTearing, WritesARowPerSizeWithFiniteFiguresAndTears) {
  const std::filesystem::path dir = test::test_output_dir("bench_tearing");
  const std::string command =
      std::string("timeout 600 ") + PHYXEL_BINARY_DIR +
      "/app/phyxel bench --tearing --sizes 3000 --tear-stress 3000 --steps 8 --repeats 1 "
      "--threads 1 --out " +
      dir.string() + " > " + (dir / "stdout.txt").string() + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0);
  const nlohmann::json j = test::read_json(dir / "tearing.json");
  ASSERT_EQ(j["tearing"].size(), 1u);
  const nlohmann::json& row = j["tearing"][0];
  for (const char* key : {"step_ms_intact", "step_ms_tearing", "tear_ms_per_step",
                          "steps_per_s_tearing", "torn_per_step"}) {
    ASSERT_TRUE(row.contains(key)) << key;
    EXPECT_TRUE(std::isfinite(row[key].get<double>())) << key;
  }
  EXPECT_GT(row["phyxels"].get<int>(), 2000);
  EXPECT_GT(row["torn_total"].get<int>(), 0);
  EXPECT_TRUE(row["finite"].get<bool>());
}

// Damaged phyxels (docs/tearing.md): tissue far weaker than its stiffness (2 kPa against E
// 100 kPa) under the fast probe tears along the probe's path and stays finite. Before damage
// weakened phyxels that lost pairs, this box crumbled (26 461 of its about 41 000 pairs torn)
// and turned non-finite.
TEST(BenchTearing, WeakTissueTearsWithoutCrumbling) {
  const std::filesystem::path dir = test::test_output_dir("bench_tearing_weak");
  const std::string command = std::string("timeout 600 ") + PHYXEL_BINARY_DIR +
                              "/app/phyxel bench --tearing --sizes 3000 --tear-stress 2000 "
                              "--steps 200 --repeats 1 --threads 1 --out " +
                              dir.string() + " > " + (dir / "stdout.txt").string() + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0);
  const nlohmann::json row = test::read_json(dir / "tearing.json")["tearing"][0];
  EXPECT_TRUE(row["finite_tearing"].get<bool>());
  EXPECT_GT(row["torn_total"].get<int>(), 100);
  EXPECT_LT(row["torn_total"].get<int>(), 8000);
}

}  // namespace
}  // namespace phyxel
