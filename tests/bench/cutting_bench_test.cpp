// `phyxel bench --cutting` end to end, short (CPU, one small box): the JSON has its row with
// finite values and the scalpel severed pairs while the probe did not. Timing never decides
// the test.
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

TEST(BenchCutting, WritesARowPerSizeWithFiniteFigures) {
  const std::filesystem::path dir = test::test_output_dir("bench_cutting");
  const std::string command = std::string("timeout 600 ") + PHYXEL_BINARY_DIR +
                              "/app/phyxel bench --cutting --sizes 3000 --steps 8 --repeats 1 "
                              "--threads 1 --out " +
                              dir.string() + " > " + (dir / "stdout.txt").string() + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0);
  const nlohmann::json j = test::read_json(dir / "cutting.json");
  ASSERT_EQ(j["cutting"].size(), 1u);
  const nlohmann::json& row = j["cutting"][0];
  for (const char* key : {"step_ms_probe", "step_ms_scalpel", "cut_ms_per_step",
                          "steps_per_s_cutting", "severed_per_step"}) {
    ASSERT_TRUE(row.contains(key)) << key;
    EXPECT_TRUE(std::isfinite(row[key].get<double>())) << key;
  }
  EXPECT_GT(row["phyxels"].get<int>(), 2000);
  EXPECT_GT(row["severed_total"].get<int>(), 0);
  EXPECT_TRUE(row["finite"].get<bool>());
}

}  // namespace
}  // namespace phyxel
