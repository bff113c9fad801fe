// `phyxel bench --skips` and `--stability` on a GPU device: the same table as on the CPU, the
// CPU's pass sizes, and soaks through the Solver interface that stay with the double reference.
#include <fstream>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "tests/gpu_solver/gpu_solver_fixture.h"
#include "tests/support/support.h"

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

using phyxel::test::read_json;

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

// Scale: a size the device cannot hold is refused with the device's message before the box
// is sampled (a billion phyxels would take the host minutes and tens of GB), the sizes before
// it still run, and --no-check leaves the CPU reference out (its error fields null).
TEST_F(GpuSolverTest, BenchRefusesASizeTheDeviceCannotHoldBeforeSamplingIt) {
  const auto json = phyxel::test::test_output_dir("gpu_bench_scale") / "scale.json";
  const std::string device = "gpu:" + std::to_string(ctx().info().index);
  testing::internal::CaptureStdout();
  const int rc = app::bench_command({"--device", device, "--sizes", "1000,1000000000", "--steps",
                                     "4", "--repeats", "1", "--no-check", "--json", json});
  const std::string out = testing::internal::GetCapturedStdout();
  ASSERT_EQ(rc, 0) << out;
  const nlohmann::json rows = read_json(json);
  ASSERT_EQ(rows.size(), 2u) << rows.dump();
  EXPECT_FALSE(rows[0].contains("refused"));
  EXPECT_TRUE(rows[0]["error_over_extent"].is_null()) << "--no-check";
  EXPECT_GT(rows[0]["gpu_bytes"].get<double>(), 0.0);
  EXPECT_GT(rows[0]["host_peak_bytes"].get<double>(), 0.0);
  EXPECT_EQ(rows[1]["phyxels"].get<int64_t>(), 1000000000);
  const std::string refused = rows[1]["refused"].get<std::string>();
  EXPECT_NE(refused.find("not enough GPU memory"), std::string::npos) << refused;
  EXPECT_NE(refused.find(ctx().info().name), std::string::npos) << refused;
  EXPECT_NE(out.find("memory: "), std::string::npos) << out;
}

// The largest binding, not the memory, is what a device may run out of first: the neighbour
// index (4 bytes per pair) past maxStorageBufferRange is refused naming the buffer.
TEST_F(GpuSolverTest, CapacityNamesTheBufferPastTheLargestBinding) {
  // The neighbour index is bound in two parts (PairBuffer): one pair past one part is held,
  // one pair past two is refused.
  const uint64_t per_part = pairs_per_part(ctx());
  for (const uint64_t pairs : {per_part + 1, 2 * per_part + 1}) {
    const uint64_t phyxels = pairs / 64 + 1;
    if (GpuSolver::required_device_bytes(phyxels, pairs) > ctx().available_device_memory()) {
      std::printf("[ skipped  ] %llu pairs: this device's memory runs out first\n",
                  static_cast<unsigned long long>(pairs));
      continue;
    }
    if (pairs == per_part + 1) {
      EXPECT_NO_THROW(GpuSolver::check_capacity(ctx(), phyxels, pairs));
      continue;
    }
    try {
      GpuSolver::check_capacity(ctx(), phyxels, pairs);
      ADD_FAILURE() << "a neighbour index of " << pairs * 4 << " bytes was accepted";
    } catch (const VulkanError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("neighbour index"), std::string::npos) << what;
      EXPECT_NE(what.find("two bindings of maxStorageBufferRange"), std::string::npos) << what;
    }
  }
  EXPECT_NO_THROW(GpuSolver::check_capacity(ctx(), 1000, 26000));
  EXPECT_THROW(GpuSolver::check_capacity(ctx(), uint64_t{1} << 31, 0), std::invalid_argument);
}

}  // namespace
}  // namespace phyxel::gpu::test
