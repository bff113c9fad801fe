// `phyxel bench --skips` and `--stability` on a GPU device: the same table as on the CPU, the
// CPU's pass sizes, and soaks through the Solver interface that stay with the double reference.
#include <fstream>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

// Runs from the source folder (the benches name scenes/*.json relative to it).
class InSourceDir {
 public:
  InSourceDir() : old_(std::filesystem::current_path()) {
    std::filesystem::current_path(PHYXEL_SOURCE_DIR);
  }
  ~InSourceDir() { std::filesystem::current_path(old_); }

 private:
  std::filesystem::path old_;
};

nlohmann::json read_json(const std::filesystem::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in);
}

TEST_F(GpuSolverTest, BenchSkipsOnTheGpuSkipsWhatTheCpuSkips) {
  const auto json = phyxel::test::test_output_dir("gpu_bench_skips") / "skips.json";
  const std::string device = "gpu:" + std::to_string(ctx().info().index);
  {
    const InSourceDir here;
    testing::internal::CaptureStdout();
    const int rc = app::bench_command({"--skips", "--device", device, "--scenes",
                                       "scenes/beam.json", "--steps", "2", "--json", json});
    const std::string out = testing::internal::GetCapturedStdout();
    ASSERT_EQ(rc, 0) << out;
    EXPECT_NE(out.find(ctx().info().name), std::string::npos) << out;
  }
  const nlohmann::json rows = read_json(json);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_NE(rows[0]["device"].get<std::string>().find(ctx().info().name), std::string::npos);
  const Scene scene = load_scene(std::string(PHYXEL_SOURCE_DIR) + "/scenes/beam.json");
  const PhyxelSet set = sample_scene(scene);
  const CpuSolver<double> cpu(set, scene.simulation.gravity);
  EXPECT_EQ(rows[0]["phyxels"], set.size());
  EXPECT_EQ(rows[0]["stress_pass_phyxels"], cpu.stress_pass_size());
}

TEST_F(GpuSolverTest, BenchStabilityOnTheGpuStaysWithTheDoubleReference) {
  const auto json = phyxel::test::test_output_dir("gpu_bench_stability") / "stability.json";
  const std::string device = "gpu:" + std::to_string(ctx().info().index);
  {
    const InSourceDir here;
    testing::internal::CaptureStdout();
    const int rc = app::bench_command(
        {"--stability", "--device", device, "--steps", "150", "--threads", "1", "--json", json});
    const std::string out = testing::internal::GetCapturedStdout();
    ASSERT_EQ(rc, 0) << out;
  }
  const nlohmann::json rows = read_json(json);
  ASSERT_EQ(rows.size(), 4u);  // two soaks, each on the GPU and in double on the CPU
  for (size_t k = 0; k < rows.size(); k += 2) {
    const nlohmann::json& g = rows[k];
    const nlohmann::json& d = rows[k + 1];
    EXPECT_EQ(g["real"], "gpu");
    EXPECT_EQ(d["real"], "double");
    EXPECT_EQ(g["soak"], d["soak"]);
    EXPECT_NE(g["device"].get<std::string>().find(ctx().info().name), std::string::npos);
    EXPECT_EQ(g["non_finite_step"], -1);
    const double moved = d["max_displacement"].get<double>();
    ASSERT_GT(moved, 0) << d["soak"];  // the soak did something
    EXPECT_LE(g["gpu_vs_double_max_u"].get<double>(), 1e-4 * moved) << g["soak"];
    EXPECT_NEAR(g["max_speed"].get<double>(), d["max_speed"].get<double>(),
                1e-3 * d["max_speed"].get<double>())
        << g["soak"];
  }
}

}  // namespace
}  // namespace phyxel::gpu::test
