// Runs of scenes that can tear (a material with tear_stress): `phyxel run --explain` lists the
// principal stress and tear passes with it and skips them without, and the .vtp points carry
// max_principal_stress (ASCII and binary) from the CPU and the GPU solver only then.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "compute/gpu_solver.h"
#include "engine/run/simulation.h"
#include "tests/physics/physics_fixtures.h"
#include "tests/support/support.h"
#include "tests/vulkan/vulkan_test.h"

namespace phyxel {
namespace {

// A 2 x 2 x 1 cm block of soft tissue on a fixed base under gravity, pressed sideways by a
// load on its top; tear_stress on the block's material (or not).
std::string scene_json(bool tear, const std::string& format = "ascii") {
  std::ostringstream j;
  j << R"({"simulation": {"dt": 1e-3, "steps": 20, "gravity": [0, 0, -9.81]},
  "objects": [{"name": "block", "shape": {"type": "box", "min": [0, 0, 0], "max": [0.02, 0.02, 0.01]},
    "spacing": 0.0025,
    "material": {"young": 1e4, "poisson": 0.3, "density": 1000, "damping": 20)"
    << (tear ? R"(, "tear_stress": 2000)" : "") << R"(},
    "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.0001]}],
    "loads": [{"region": {"type": "box", "min": [-1, -1, 0.0099], "max": [1, 1, 1]},
               "force": [0.05, 0, 0]}]}],
  "output": {"every": 0, "format": ")"
    << format << R"("}})";
  return j.str();
}

std::filesystem::path write_scene(const std::filesystem::path& dir, bool tear) {
  const auto file = dir / (tear ? "tear.json" : "no_tear.json");
  std::ofstream(file) << scene_json(tear);
  return file;
}

using phyxel::test::exit_status;
using phyxel::test::read_text;

// The values of an ASCII data array of a .vtp file (empty when there is no such array).
std::vector<double> ascii_array(const std::string& text, const std::string& name) {
  const size_t at = text.find("Name=\"" + name + "\"");
  if (at == std::string::npos) return {};
  const size_t open = text.find('>', at) + 1;
  std::istringstream in(text.substr(open, text.find("</DataArray>", open) - open));
  std::vector<double> values;
  for (double v; in >> v;) values.push_back(v);
  return values;
}

// `phyxel run SCENE --explain`: its exit status and output.
std::pair<int, std::string> explain(const std::filesystem::path& scene) {
  const std::string command = PHYXEL_BINARY_DIR "/app/phyxel run " + scene.string() +
                              " --explain --out " + scene.parent_path().string() + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return {-1, ""};
  std::string out;
  char buffer[512];
  while (std::fgets(buffer, sizeof buffer, pipe)) out += buffer;
  const int status = pclose(pipe);
  return {exit_status(status), out};
}

TEST(TearingRun, ExplainRunsThePrincipalAndTearPassesOnlyWithTearStress) {
  const auto dir = test::test_output_dir("tearing_explain");
  auto [code, out] = explain(write_scene(dir, true));
  ASSERT_EQ(code, 0) << out;
  EXPECT_NE(out.find("    principal      "), std::string::npos) << out;
  EXPECT_NE(out.find("(1 material(s) with tear_stress)"), std::string::npos) << out;
  EXPECT_NE(out.find("    tear           "), std::string::npos) << out;
  EXPECT_EQ(out.find("(no material has tear_stress)"), std::string::npos) << out;

  std::tie(code, out) = explain(write_scene(dir, false));
  ASSERT_EQ(code, 0) << out;
  EXPECT_EQ(out.find("    principal      "), std::string::npos) << out;
  EXPECT_EQ(out.find("    tear           "), std::string::npos) << out;
  const size_t skipped = out.find("not recorded:");
  ASSERT_NE(skipped, std::string::npos) << out;
  EXPECT_NE(out.substr(skipped, out.find('\n', skipped) - skipped)
                .find("principal stress and tear passes (no material has tear_stress)"),
            std::string::npos)
      << out;
}

// Runs the scene (20 steps) on `solver` into `dir`; returns the last .vtp's text.
std::string run_to_points(const Scene& scene, const PhyxelSet& set, Solver& solver,
                          const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  RunOptions options;
  options.steps = scene.simulation.steps;
  options.out_dir = dir;
  const RunResult result = run_simulation(scene, set, solver, options);
  EXPECT_FALSE(result.non_finite);
  EXPECT_EQ(result.steps_done, 20);
  return read_text(dir / "points_000020.vtp");
}

TEST(TearingRun, PointsCarryTheLargestPrincipalStressOnlyWhenTearingIsPossible) {
  const auto dir = test::test_output_dir("tearing_points");
  for (const bool tear : {true, false}) {
    const Scene scene = parse_scene(scene_json(tear), dir / "scene.json");
    ASSERT_EQ(scene.tearing_possible(), tear);
    const PhyxelSet set = sample_scene(scene);
    const auto solver = make_cpu_solver(set, scene.simulation.gravity, 1);
    const std::string text = run_to_points(scene, set, *solver, dir);
    const std::vector<double> sigma = ascii_array(text, "max_principal_stress");
    if (!tear) {
      EXPECT_TRUE(sigma.empty());
      EXPECT_TRUE(solver->read_state(true).max_principal_stress.empty());
      continue;
    }
    ASSERT_EQ(sigma.size(), set.size());
    const std::vector<double> state = solver->read_state(true).max_principal_stress;
    double largest = 0;
    for (size_t i = 0; i < set.size(); ++i) {
      EXPECT_DOUBLE_EQ(sigma[i], state[i]) << i;
      largest = std::max(largest, sigma[i]);
    }
    EXPECT_GT(largest, 10);  // Pa: the load and gravity stress the block
  }
}

class TearingRunGpu : public gpu::VulkanTest {};

TEST_F(TearingRunGpu, GpuPointsCarryTheLargestPrincipalStressOfTheCpu) {
  const auto dir = test::test_output_dir("tearing_points_gpu");
  const Scene scene = parse_scene(scene_json(true, "binary"), dir / "scene.json");
  const PhyxelSet set = sample_scene(scene);
  const auto cpu = make_cpu_solver(set, scene.simulation.gravity, 1);
  run_to_points(scene, set, *cpu, dir / "cpu");
  gpu::GpuSolver gpu(ctx(), set, scene.simulation.gravity);
  const std::string text = run_to_points(scene, set, gpu, dir / "gpu");
  EXPECT_NE(text.find("Name=\"max_principal_stress\""), std::string::npos);  // binary
  const std::vector<double> want = cpu->read_state(true).max_principal_stress;
  const std::vector<double> got = gpu.read_state(true).max_principal_stress;
  ASSERT_EQ(got.size(), set.size());
  double largest = 0;
  for (double v : want) largest = std::max(largest, std::abs(v));
  ASSERT_GT(largest, 10);
  for (size_t i = 0; i < set.size(); ++i)
    EXPECT_NEAR(got[i], want[i], 1e-3 * largest) << "phyxel " << i;
}

}  // namespace
}  // namespace phyxel
