// The GPU solver behind the Solver interface: make_gpu_solver with the run loop, and
// `phyxel run --device gpu` end to end (summary.json and .vtp like the CPU path), including
// the one-line error without a Vulkan loader.
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>

#include "app/commands.h"
#include "tests/gpu_solver/gpu_solver_fixture.h"
#include "tests/support/scoped_env.h"
#include "tests/support/support.h"

namespace phyxel::gpu::test {
namespace {

std::filesystem::path out_dir(const std::string& name) {
  const char* root = std::getenv("PHYXEL_TEST_OUT");
  std::filesystem::path dir = std::filesystem::path(root ? root : "/tmp") / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

using phyxel::test::read_json;

using phyxel::test::ScopedEnv;

constexpr const char* kScene = R"({
  "simulation": {"dt": 1e-4, "steps": 40, "gravity": [0, 0, -9.81]},
  "objects": [{
    "name": "block",
    "shape": {"type": "box", "min": [0, 0, 0], "max": [0.015, 0.01, 0.0075]},
    "spacing": 0.0025,
    "material": {"young": 1e5, "poisson": 0.3, "density": 1000, "damping": 5.0},
    "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.001]}]
  }],
  "output": {"every": 20}
})";

TEST_F(GpuSolverTest, RunLoopThroughTheSolverInterfaceMatchesTheCpu) {
  const Scene scene = parse_scene(kScene, "inline.json");
  const PhyxelSet set = sample_scene(scene);
  std::unique_ptr<Solver> gpu = make_gpu_solver(set, scene.simulation.gravity, ctx().options());
  const auto log = static_cast<GpuSolver&>(*gpu).context().validation_log();
  EXPECT_NE(gpu->device().find(ctx().info().name), std::string::npos) << gpu->device();
  EXPECT_EQ(gpu->device().rfind("gpu:", 0), 0u) << gpu->device();
  RunOptions options;
  options.steps = 40;
  const std::filesystem::path run_dir = out_dir("gpu_solver_run_loop");
  options.out_dir = run_dir;
  const RunResult g = run_simulation(scene, set, *gpu, options);
  gpu.reset();
  expect_no_validation_messages(log);

  auto cpu = make_cpu_solver(set, scene.simulation.gravity, 1);
  options.out_dir.clear();
  const RunResult c = run_simulation(scene, set, *cpu, options);
  EXPECT_FALSE(g.non_finite);
  EXPECT_EQ(g.steps_done, 40);
  EXPECT_EQ(g.outputs, (std::vector<std::string>{"points_000020.vtp", "points_000040.vtp"}));
  for (const std::string& f : g.outputs) EXPECT_TRUE(std::filesystem::exists(run_dir / f)) << f;
  ASSERT_GT(c.max_displacement, 0);
  EXPECT_NEAR(g.max_displacement, c.max_displacement, 1e-4 * c.max_displacement);
  EXPECT_NEAR(g.energies.kinetic, c.energies.kinetic, 1e-3 * c.energies.kinetic);
  EXPECT_NEAR(g.energies.strain, c.energies.strain, 1e-3 * c.energies.strain);
  EXPECT_NEAR(g.energies.potential, c.energies.potential, 1e-4 * std::abs(c.energies.potential));
}

TEST_F(GpuSolverTest, PhyxelRunOnTheGpuWritesTheCpuOutputs) {
  const auto dir = out_dir("gpu_solver_cli");
  const auto scene_file = dir / "scene.json";
  std::ofstream(scene_file) << kScene;
  std::vector<std::string> gpu_args = {scene_file.string(), "--device", "gpu",
                                       "--quiet",           "--out",    (dir / "gpu").string()};
  if (ctx().validation_log() != nullptr) gpu_args.push_back("--validate");
  ASSERT_EQ(app::run_command(gpu_args), 0);
  ASSERT_EQ(app::run_command({scene_file.string(), "--device", "cpu", "--threads", "1", "--quiet",
                              "--out", (dir / "cpu").string()}),
            0);
  const nlohmann::json g = read_json(dir / "gpu" / "summary.json");
  const nlohmann::json c = read_json(dir / "cpu" / "summary.json");
  EXPECT_NE(g["device"].get<std::string>().find(ctx().info().name), std::string::npos);
  for (const char* key : {"phyxels", "steps_done", "substeps_per_step", "objects", "outputs",
                          "ill_conditioned_moment_matrices", "non_finite"})
    EXPECT_EQ(g[key], c[key]) << key;
  EXPECT_NEAR(g["max_displacement"].get<double>(), c["max_displacement"].get<double>(),
              1e-4 * c["max_displacement"].get<double>());
  for (const auto& name : g["outputs"]) {
    const auto file = dir / "gpu" / name.get<std::string>();
    EXPECT_GT(std::filesystem::file_size(file), 0u) << file;
  }
}

TEST_F(GpuSolverTest, PhyxelRunWithoutAVulkanLoaderSaysUseTheCpu) {
  const auto dir = out_dir("gpu_solver_no_loader");
  const auto scene_file = dir / "scene.json";
  std::ofstream(scene_file) << kScene;
  const ScopedEnv loader("PHYXEL_VULKAN_LOADER", "/nonexistent/libvulkan.so.1");
  testing::internal::CaptureStderr();
  const int rc = app::run_command(
      {scene_file.string(), "--device", "gpu", "--quiet", "--out", (dir / "out").string()});
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(rc, 1);
  EXPECT_NE(err.find("--device cpu"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "summary.json"));
}

}  // namespace
}  // namespace phyxel::gpu::test
