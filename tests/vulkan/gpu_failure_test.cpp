// GPU failures during a run: out of device memory and a lost device, forced through the test
// hooks of the memory layer and the submit path (compute/context.h). Each is one line naming
// the device and what failed (for memory: the buffer and its size) and what to do; the points
// files written before the failure stay whole, and `phyxel run` says the step it reached.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "compute/buffer.h"
#include "compute/gpu_solver.h"
#include "engine/run/simulation.h"
#include "tests/physics/physics_fixtures.h"
#include "tests/support/scoped_env.h"
#include "tests/support/support.h"
#include "vulkan_test.h"

namespace phyxel::gpu {
namespace {

namespace fs = std::filesystem;
using GpuFailureTest = VulkanTest;

using phyxel::test::exit_status;
using phyxel::test::read_text;

// A whole points file: it ends with the closing tag.
void expect_whole_points_file(const fs::path& file) {
  const std::string text = read_text(file);
  ASSERT_GT(text.size(), 100u) << file;
  EXPECT_EQ(text.substr(text.size() - 11), "</VTKFile>\n") << file;
}

void expect_no_temporary_files(const fs::path& dir) {
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_NE(entry.path().extension(), ".tmp") << entry.path();
}

void expect_out_of_memory_message(const std::string& msg, const Context& ctx,
                                  const std::string& buffer) {
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  for (const std::string& part :
       {"out of GPU memory on " + ctx.info().name, "for buffer '" + buffer,
        std::string("VK_ERROR_OUT_OF_DEVICE_MEMORY"), std::string("or run with --device cpu")})
    EXPECT_NE(msg.find(part), std::string::npos) << "no \"" << part << "\" in: " << msg;
}

TEST_F(GpuFailureTest, AllocationHookFailsTheAllocationsAfterTheFirstN) {
  const uint64_t before = ctx().allocated_bytes();
  ctx().set_test_fail_allocation_after(2);
  const Buffer a(ctx(), 1024, MemoryIntent::Device, "first");
  const Buffer b(ctx(), 1024, MemoryIntent::Readback, "second");
  try {
    const Buffer c(ctx(), 3 << 20, MemoryIntent::Device, "third");
    FAIL() << "the third allocation succeeded";
  } catch (const VulkanError& e) {
    EXPECT_EQ(e.result(), VK_ERROR_OUT_OF_DEVICE_MEMORY);
    expect_out_of_memory_message(e.what(), ctx(), "third");
    EXPECT_NE(std::string(e.what()).find("allocating 3.0 MiB of device memory"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(Buffer(ctx(), 16, MemoryIntent::Upload, "fourth"), VulkanError);  // stays full
  ctx().set_test_fail_allocation_after(-1);
  EXPECT_NO_THROW(Buffer(ctx(), 16, MemoryIntent::Upload, "fifth"));
  EXPECT_EQ(ctx().allocated_bytes(), before + a.size() + b.size());
}

TEST_F(GpuFailureTest, AllocationHookIsReadFromTheEnvironment) {
  const phyxel::test::ScopedEnv hook("PHYXEL_TEST_FAIL_ALLOC_AFTER", "1");
  Context& c = make_context();
  EXPECT_NO_THROW(Buffer(c, 64, MemoryIntent::Device, "one"));
  EXPECT_THROW(Buffer(c, 64, MemoryIntent::Device, "two"), VulkanError);
}

// A small block sagging under gravity, a points file every 5 steps, one substep per step.
struct RunSetup {
  Scene scene;
  PhyxelSet set;
  RunOptions options;
};

RunSetup block_run(const std::string& name) {
  RunSetup r;
  r.scene = phyxel::test::box_scene(Vec3(0, 0, 0), Vec3(0.01, 0.005, 0.005), 0.0025,
                                    phyxel::test::tissue(1e5, 0.3, 20));
  r.scene.simulation.gravity = Vec3(0, 0, -9.81);
  r.scene.output.every = 5;
  r.set = sample_scene(r.scene);
  r.scene.simulation.dt = plan_time_step(r.scene, r.set).dt_stable;
  r.options.steps = 20;
  r.options.out_dir = phyxel::test::test_output_dir("gpu_failure_" + name);
  return r;
}

TEST_F(GpuFailureTest, OutOfMemoryMidRunKeepsTheEarlierPointsFiles) {
  RunSetup r = block_run("oom");
  GpuSolver solver(ctx(), r.set, r.scene.simulation.gravity);
  // From step 11 on, every allocation fails (whichever comes next: the state's read-back
  // buffer is made once, by the first points file, so a later one).
  r.options.progress = [&](int64_t step, int64_t) {
    if (step > 10) ctx().set_test_fail_allocation_after(0);
  };
  try {
    run_simulation(r.scene, r.set, solver, r.options);
    FAIL() << "the run finished despite the allocation failures";
  } catch (const VulkanError& e) {
    EXPECT_EQ(e.result(), VK_ERROR_OUT_OF_DEVICE_MEMORY);
    expect_out_of_memory_message(e.what(), ctx(), "");
  }
  ctx().set_test_fail_allocation_after(-1);
  expect_whole_points_file(r.options.out_dir / "points_000005.vtp");
  expect_whole_points_file(r.options.out_dir / "points_000010.vtp");
  // Whatever was written after step 10 and before the failure is whole too.
  if (fs::exists(r.options.out_dir / "points_000015.vtp"))
    expect_whole_points_file(r.options.out_dir / "points_000015.vtp");
  expect_no_temporary_files(r.options.out_dir);
}

TEST_F(GpuFailureTest, DeviceLostMidRunKeepsTheEarlierPointsFiles) {
  const phyxel::test::ScopedEnv hook("PHYXEL_TEST_DEVICE_LOST_AT_SUBSTEP", "12");
  Context& c = make_context();
  RunSetup r = block_run("lost");
  GpuSolver solver(c, r.set, r.scene.simulation.gravity);
  try {
    run_simulation(r.scene, r.set, solver, r.options);
    FAIL() << "the run finished on a lost device";
  } catch (const VulkanError& e) {
    EXPECT_EQ(e.result(), VK_ERROR_DEVICE_LOST);
    EXPECT_NE(std::string(e.what()).find("VK_ERROR_DEVICE_LOST"), std::string::npos) << e.what();
  }
  expect_whole_points_file(r.options.out_dir / "points_000005.vtp");
  expect_whole_points_file(r.options.out_dir / "points_000010.vtp");
  // Whatever was written after step 10 and before the failure is whole too.
  if (fs::exists(r.options.out_dir / "points_000015.vtp"))
    expect_whole_points_file(r.options.out_dir / "points_000015.vtp");
  expect_no_temporary_files(r.options.out_dir);
}

// `phyxel run --device gpu` (on the test device) with the hooks set in its environment, of a
// block of 4 x 2 x 2 phyxels (or finer with a smaller spacing).
std::pair<int, std::string> phyxel_run(const fs::path& dir, const std::string& env,
                                       const std::string& spacing = "0.0025") {
  const std::string device = test_context_options().device;  // also points the loader
  std::ofstream(dir / "block.json") << R"({
  "simulation": {"dt": 1e-5, "steps": 40},
  "objects": [{"name": "block", "shape": {"type": "box", "min": [0, 0, 0],
               "max": [0.01, 0.005, 0.005]}, "spacing": )"
                                    << spacing << R"(,
               "material": {"young": 1e5, "poisson": 0.3, "density": 1000, "damping": 20},
               "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [0.001, 1, 1]}]}],
  "output": {"every": 10}
})";
  const std::string cmd = env + " " + std::string(PHYXEL_BINARY_DIR) + "/app/phyxel run " +
                          (dir / "block.json").string() + " --device " + device +
                          " --quiet --out " + dir.string() + " 2>" + (dir / "err.txt").string();
  const int status = std::system(cmd.c_str());
  return {exit_status(status), read_text(dir / "err.txt")};
}

TEST(GpuFailureCli, DeviceLostIsOneLineWithTheStepReached) {
  const fs::path dir = phyxel::test::test_output_dir("gpu_failure_cli_lost");
  const auto [code, err] = phyxel_run(dir, "PHYXEL_TEST_DEVICE_LOST_AT_SUBSTEP=25");
  EXPECT_EQ(code, 1) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  for (const char* part : {"block.json after step 20 of 40: ", "VK_ERROR_DEVICE_LOST",
                           "the GPU was lost", "the last: points_000020.vtp"})
    EXPECT_NE(err.find(part), std::string::npos) << "no \"" << part << "\" in: " << err;
  expect_whole_points_file(dir / "points_000010.vtp");
  expect_whole_points_file(dir / "points_000020.vtp");
  EXPECT_FALSE(fs::exists(dir / "points_000030.vtp"));
  EXPECT_FALSE(fs::exists(dir / "summary.json"));
  expect_no_temporary_files(dir);
}

TEST(GpuFailureCli, OutOfMemoryAtSetupIsOneLineNamingTheBuffer) {
  const fs::path dir = phyxel::test::test_output_dir("gpu_failure_cli_oom");
  const auto [code, err] = phyxel_run(dir, "PHYXEL_TEST_FAIL_ALLOC_AFTER=0");
  EXPECT_EQ(code, 1) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  for (const char* part :
       {"block.json while setting up: out of GPU memory on ", "for buffer '",
        "VK_ERROR_OUT_OF_DEVICE_MEMORY", "--device cpu", "no points file was written"})
    EXPECT_NE(err.find(part), std::string::npos) << "no \"" << part << "\" in: " << err;
  expect_no_temporary_files(dir);
}

// A submission the GPU does not finish in time (here every one: a timeout of 0 ms, with work
// enough that lavapipe's threads still run it) is one line, and the process ends without
// freeing what that work reads: before, the buffers and pipelines were freed under it (a
// crash on lavapipe, SIGSEGV, found when a loaded machine took over 120 s for one frame).
TEST(GpuFailureCli, WorkNotFinishedInTimeIsOneLineAndNoCrash) {
  const fs::path dir = phyxel::test::test_output_dir("gpu_failure_cli_timeout");
  const auto [code, err] = phyxel_run(dir, "PHYXEL_TEST_FENCE_TIMEOUT_MS=0", "0.00025");
  EXPECT_EQ(code, 1) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  for (const char* part : {"block.json while setting up: ", "the GPU did not finish '",
                           "within 0 ms", "--device cpu", "PHYXEL_GPU_TIMEOUT_S"})
    EXPECT_NE(err.find(part), std::string::npos) << "no \"" << part << "\" in: " << err;
  expect_no_temporary_files(dir);
}

TEST(GpuFailureCli, AMalformedTimeoutIsOneLineNamingTheVariable) {
  const fs::path dir = phyxel::test::test_output_dir("gpu_failure_cli_bad_timeout");
  const auto [code, err] = phyxel_run(dir, "PHYXEL_GPU_TIMEOUT_S=2m");
  EXPECT_EQ(code, 1) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  EXPECT_NE(err.find("PHYXEL_GPU_TIMEOUT_S='2m' is not a whole number of seconds"),
            std::string::npos)
      << err;
}

// A CPU driver waits at least 10 min for a submission, a GPU 120 s; the variable sets both.
TEST(GpuTimeout, ACpuDriverWaitsLongerAndTheVariableSetsTheWait) {
  const ContextOptions options = test_context_options();
  {
    const Context plain(options);
    const bool cpu = plain.info().type == VK_PHYSICAL_DEVICE_TYPE_CPU;
    EXPECT_EQ(plain.options().fence_timeout_ms, cpu ? 600000u : 120000u);
  }
  {
    const phyxel::test::ScopedEnv env("PHYXEL_GPU_TIMEOUT_S", "7");
    EXPECT_EQ(Context(options).options().fence_timeout_ms, 7000u);
  }
  for (const char* bad : {"0", "-5", "2m", "86401"}) {
    const phyxel::test::ScopedEnv env("PHYXEL_GPU_TIMEOUT_S", bad);
    EXPECT_THROW(Context{options}, VulkanError) << bad;
  }
}

}  // namespace
}  // namespace phyxel::gpu
