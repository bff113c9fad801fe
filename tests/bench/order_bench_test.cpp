// `phyxel bench --device gpu --order lattice,morton` end to end, short (lavapipe, one small
// box): a row per order, both finite, as close to the CPU reference as each other (the
// numbering changes the order of the neighbour sums, not the physics) and without an
// ill-conditioned moment matrix; an unknown order is a usage error. Timing never decides the test.
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

TEST(BenchOrder, LatticeAndMortonRowsAgreeWithTheCpu) {
  const std::filesystem::path dir = test::test_output_dir("bench_order");
  const std::string command =
      std::string("timeout 600 ") + PHYXEL_BINARY_DIR +
      "/app/phyxel bench --device gpu --sizes 1500 --steps 4 --repeats 1 --check-steps 20 "
      "--order lattice,morton --json " +
      (dir / "bench.json").string() + " > " + (dir / "stdout.txt").string() + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0);
  const nlohmann::json j = test::read_json(dir / "bench.json");
  std::vector<nlohmann::json> gpu_rows;
  for (const nlohmann::json& row : j)
    if (row.value("backend", "") == "gpu") gpu_rows.push_back(row);
  ASSERT_EQ(gpu_rows.size(), 2u);
  EXPECT_EQ(gpu_rows[0]["order"], "lattice");
  EXPECT_EQ(gpu_rows[1]["order"], "morton");
  EXPECT_EQ(gpu_rows[0]["phyxels"], gpu_rows[1]["phyxels"]);
  for (const nlohmann::json& row : gpu_rows) {
    EXPECT_TRUE(row["finite"].get<bool>());
    EXPECT_GT(row["phyxel_steps_per_second"].get<double>(), 0.0);
    EXPECT_LT(row["error_over_max_displacement"].get<double>(), 1e-4);
    // Every phyxel of the box has a full neighbourhood, in either numbering.
    EXPECT_EQ(row["ill_conditioned_moment_matrices"].get<int>(), 0);
  }
  const std::string bad = std::string(PHYXEL_BINARY_DIR) +
                          "/app/phyxel bench --device gpu --order zorder > " +
                          (dir / "bad.txt").string() + " 2>&1";
  EXPECT_EQ(WEXITSTATUS(std::system(bad.c_str())), 2);
  std::ifstream bad_in(dir / "bad.txt");
  const std::string said((std::istreambuf_iterator<char>(bad_in)), {});
  EXPECT_NE(said.find("--order zorder: 'zorder' is not lattice or morton"), std::string::npos)
      << said;
}

}  // namespace
}  // namespace phyxel
