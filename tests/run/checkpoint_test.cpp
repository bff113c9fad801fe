// Checkpoint and resume (engine/run/checkpoint.h, docs/checkpoint.md): the file format's
// refusals (truncated, bit-flipped, another version, another scene, missing), and `phyxel run
// --checkpoint-every N` / `--resume DIR` end to end: the resumed run's final state is
// bit-identical to the uninterrupted run's on the CPU and on the GPU (lavapipe), with loads
// switching, objects sleeping and a path tool (tools.csv). Every run is bounded by --steps
// and `timeout`.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "compute/test_env.h"
#include "engine/run/checkpoint.h"
#include "engine/run/checkpoint_format.h"
#include "engine/run/simulation.h"
#include "engine/scene/scene.h"
#include "engine/solver/cutting.h"
#include "engine/solver/solver.h"
#include "tests/physics/physics_fixtures.h"
#include "tests/run/checkpoint_fixtures.h"
#include "tests/support/support.h"

namespace phyxel {
namespace {

namespace fs = std::filesystem;

using checkpoint_test::gpu_device_args;
using checkpoint_test::kScalpel;
using checkpoint_test::Ran;
using checkpoint_test::run;
using checkpoint_test::write_bytes;
using checkpoint_test::write_scene;
using phyxel::test::exit_status;
using phyxel::test::kPhyxel;
using phyxel::test::read_json;
using phyxel::test::read_text;

// Two objects, no gravity: a cantilever whose tip load acts from step 100 to step 200 (before
// it, and once it has settled, the cantilever sleeps; the load's switches wake it) and a block
// that nothing moves (asleep from the first checks on). 2 substeps per step.
constexpr const char* kBeams = R"({
  "simulation": {"dt": 5e-5, "steps": 400, "gravity": [0, 0, 0],
                 "sleep": {"kinetic_energy_below": 1e-9, "for_steps": 20}},
  "objects": [
    {"name": "beam", "shape": {"type": "box", "min": [0, -0.005, -0.005], "max": [0.04, 0.005, 0.005]},
     "spacing": 0.0025,
     "material": {"young": 1e6, "poisson": 0.3, "density": 1000, "damping": 20},
     "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [0.0005, 1, 1]}],
     "loads": [{"region": {"type": "box", "min": [0.0395, -1, -1], "max": [1, 1, 1]},
                "force": [0, 0, -0.05], "from": 0.005, "until": 0.01}]},
    {"name": "block", "shape": {"type": "box", "min": [0, 0.02, 0], "max": [0.01, 0.03, 0.01]},
     "spacing": 0.0025,
     "material": {"young": 1e6, "poisson": 0.3, "density": 1000, "damping": 2},
     "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.0005]}]}],
  "output": {"every": 100, "format": "binary"}
})";

// A block and a sphere probe pressing into it along a path (the scene of tools_run_test).
constexpr const char* kProbe = R"({
  "simulation": {"dt": 1e-3, "steps": 60, "gravity": [0, 0, 0]},
  "objects": [{"name": "block", "shape": {"type": "box", "min": [0, 0, 0], "max": [0.02, 0.02, 0.01]},
    "spacing": 0.0025,
    "material": {"young": 1e4, "poisson": 0.3, "density": 1000, "damping": 20},
    "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.001]}]}],
  "output": {"every": 20, "format": "binary"},
  "tools": [{"name": "probe", "type": "probe", "shape": {"type": "sphere", "radius": 0.003},
     "path": [{"t": 0, "position": [0.01, 0.01, 0.017]}, {"t": 0.02, "position": [0.01, 0.01, 0.015]},
              {"t": 0.06, "position": [0.01, 0.01, 0.009]}], "friction": 0.2}]
})";

// A grasper closing on the end of a strip at 5 ms, pulling it until it lets go at 40 ms: the
// checkpoints at 20 ms (and a stop at 27 ms) fall inside the grip.
constexpr const char* kGrasper = R"({
  "simulation": {"dt": 1e-3, "steps": 60, "gravity": [0, 0, 0]},
  "objects": [{"name": "strip", "shape": {"type": "box", "min": [0, -0.004, -0.003], "max": [0.03, 0.004, 0.003]},
    "spacing": 0.002,
    "material": {"young": 5e3, "poisson": 0.4, "density": 1000, "damping": 60},
    "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [0.0025, 1, 1]}]}],
  "output": {"every": 20, "format": "binary"},
  "tools": [{"name": "grasper", "type": "grasper", "shape": {"type": "sphere", "radius": 0.001},
     "grasp": {"reach": 0.005, "from": 0.005, "until": 0.04},
     "path": [{"t": 0, "position": [0.0315, 0, 0]}, {"t": 0.005, "position": [0.0315, 0, 0]},
              {"t": 0.04, "position": [0.0365, 0.002, 0.001]}]}]
})";

// The resumed run's outputs equal the uninterrupted run's byte for byte.
void expect_same_file(const fs::path& a, const fs::path& b) {
  ASSERT_TRUE(fs::exists(a)) << a;
  ASSERT_TRUE(fs::exists(b)) << b;
  EXPECT_TRUE(read_text(a) == read_text(b)) << a << " and " << b << " differ";
}

// Runs the scene uninterrupted without checkpoints (plain), with them (full), and cut at
// `stop` then resumed (part); the last state of all three must match bitwise.
void check_resume(const fs::path& dir, const fs::path& scene, const std::string& args,
                  int64_t total, int64_t every, int64_t stop) {
  const std::string steps = " --steps " + std::to_string(total);
  const std::string ck = " --checkpoint-every " + std::to_string(every);
  fs::create_directories(dir);
  Ran r = run(scene, args + steps + " --out " + (dir / "plain").string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run(scene, args + steps + ck + " --out " + (dir / "full").string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run(scene,
          args + " --steps " + std::to_string(stop) + ck + " --out " + (dir / "part").string(),
          dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(read_checkpoint(dir / "part" / kCheckpointFile).step, stop);
  r = run(scene, args + steps + " --resume " + (dir / "part").string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;

  char last[64];
  std::snprintf(last, sizeof last, "points_%06lld.vtp", static_cast<long long>(total));
  expect_same_file(dir / "plain" / last, dir / "part" / last);
  expect_same_file(dir / "full" / last, dir / "part" / last);
  // The final checkpoints hold u and v as the solver has them: equal bit for bit.
  const Checkpoint a = read_checkpoint(dir / "full" / kCheckpointFile);
  const Checkpoint b = read_checkpoint(dir / "part" / kCheckpointFile);
  ASSERT_EQ(a.step, total);
  ASSERT_EQ(b.step, total);
  ASSERT_EQ(a.displacement.size(), b.displacement.size());
  EXPECT_EQ(0, std::memcmp(a.displacement.data(), b.displacement.data(),
                           a.displacement.size() * sizeof(Vec3)));
  EXPECT_EQ(0, std::memcmp(a.velocity.data(), b.velocity.data(), a.velocity.size() * sizeof(Vec3)));
  EXPECT_EQ(a.awake, b.awake);
  // summary.json covers the whole run.
  const nlohmann::json p = read_json(dir / "plain" / "summary.json");
  const nlohmann::json s = read_json(dir / "part" / "summary.json");
  EXPECT_EQ(s["steps_done"], total);
  EXPECT_EQ(s["resumed_from_step"], stop);
  for (const char* key : {"sleeps", "wakes", "load_changes", "max_displacement"})
    if (p.contains(key)) {
      EXPECT_EQ(s[key], p[key]) << key;
    }
}

TEST(Checkpoint, CpuResumeIsBitIdenticalAcrossLoadsAndSleep) {
  const fs::path dir = test::test_output_dir("checkpoint_cpu");
  const fs::path scene = write_scene(dir, "beams.json", kBeams);
  // Cut between the load's switches, at a checkpoint step.
  check_resume(dir / "at150", scene, "--threads 1", 400, 50, 150);
  const nlohmann::json s = read_json(dir / "at150" / "plain" / "summary.json");
  EXPECT_GT(s["sleeps"].get<int>(), 0) << s.dump(2);  // the scene exercises what it should
  EXPECT_GT(s["wakes"].get<int>(), 0) << s.dump(2);
  EXPECT_EQ(s["load_changes"].get<int>(), 2);
  // Cut at a step that is no checkpoint, check or output step.
  check_resume(dir / "at137", scene, "--threads 2", 400, 50, 137);
  // Checkpointed with one thread, resumed with two: the CPU's sums have a fixed order.
  const fs::path mixed = dir / "mixed";
  Ran r = run(scene, "--threads 1 --steps 150 --checkpoint-every 50 --out " + mixed.string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run(scene, "--threads 2 --resume " + mixed.string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  expect_same_file(dir / "at150" / "plain" / "points_000400.vtp", mixed / "points_000400.vtp");
}

// An interrupted run (stop_requested, as the viewer's close and signals stop it) leaves a
// checkpoint at the step it stopped at, from which the run goes on bit-identically.
TEST(Checkpoint, InterruptedRunResumesBitIdentically) {
  const fs::path dir = test::test_output_dir("checkpoint_interrupted");
  const Scene scene = load_scene(write_scene(dir, "beams.json", kBeams));
  const PhyxelSet set = sample_scene(scene);
  auto run_to = [&](const fs::path& out, int64_t checkpoint_every, int64_t stop_after,
                    const Checkpoint* resume) {
    fs::create_directories(out);
    auto solver = make_cpu_solver(set, scene.simulation.gravity, 1);
    RunOptions options;
    options.steps = 400;
    options.out_dir = out;
    options.checkpoint_every = checkpoint_every;
    options.resume = resume;
    int64_t seen = 0;
    options.progress = [&seen](int64_t step, int64_t) { seen = step; };
    options.stop_requested = [&seen, stop_after] { return seen >= stop_after; };
    const RunResult r = run_simulation(scene, set, *solver, options);
    return std::make_pair(r, solver->read_state(false));
  };
  const auto [plain, plain_state] = run_to(dir / "plain", 0, 400, nullptr);
  ASSERT_EQ(plain.steps_done, 400);
  const auto [cut, cut_state] = run_to(dir / "cut", 50, 173, nullptr);
  ASSERT_GE(cut.steps_done, 173);
  ASSERT_LT(cut.steps_done, 400);
  const Checkpoint c = read_checkpoint(dir / "cut" / kCheckpointFile);
  EXPECT_EQ(c.step, cut.steps_done);
  EXPECT_NE(c.step % 50, 0);  // written for the interruption, not by the schedule
  const auto [resumed, state] = run_to(dir / "cut", 50, 400, &c);
  EXPECT_EQ(resumed.steps_done, 400);
  EXPECT_EQ(resumed.resumed_from, c.step);
  EXPECT_EQ(resumed.sleeps, plain.sleeps);
  EXPECT_EQ(resumed.wakes, plain.wakes);
  ASSERT_EQ(state.displacement.size(), plain_state.displacement.size());
  EXPECT_EQ(0, std::memcmp(state.displacement.data(), plain_state.displacement.data(),
                           state.displacement.size() * sizeof(Vec3)));
  EXPECT_EQ(0, std::memcmp(state.velocity.data(), plain_state.velocity.data(),
                           state.velocity.size() * sizeof(Vec3)));
}

TEST(Checkpoint, GpuResumeIsBitIdentical) {
  std::string why;
  const std::optional<std::string> gpu_args = gpu_device_args(why);
  if (!gpu_args) GTEST_SKIP() << why;
  const std::string& device = *gpu_args;
  const fs::path dir = test::test_output_dir("checkpoint_gpu");
  const fs::path scene = write_scene(dir, "beams.json", kBeams);
  check_resume(dir / "at150", scene, device, 300, 50, 150);
  // Cut inside an advance of the uninterrupted run (it checks every 2 steps): the GPU's step
  // passes split there give the same bits as the fused ones.
  check_resume(dir / "at137", scene, device, 300, 50, 137);
  // A CPU checkpoint is refused on the GPU: its results would differ.
  const Ran r = run(
      scene, "--threads 1 --steps 100 --checkpoint-every 50 --out " + (dir / "cpu").string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const Ran g = run(scene, device + " --steps 300 --resume " + (dir / "cpu").string(), dir);
  EXPECT_EQ(g.code, 1);
  EXPECT_NE(g.err.find("same device"), std::string::npos) << g.err;
}

// The shipped cantilever (scenes/beam.json), cut at a checkpoint and inside an advance, on the
// CPU and on the GPU.
TEST(Checkpoint, BeamResumeIsBitIdenticalOnTheCpuAndTheGpu) {
  const fs::path dir = test::test_output_dir("checkpoint_beam");
  const fs::path beam = fs::path(PHYXEL_SOURCE_DIR) / "scenes" / "beam.json";
  check_resume(dir / "cpu", beam, "--threads 2", 200, 50, 100);
  check_resume(dir / "cpu_inside", beam, "--threads 1", 200, 50, 137);
  std::string why;
  const std::optional<std::string> gpu_args = gpu_device_args(why);
  if (!gpu_args) GTEST_SKIP() << why;
  const std::string& device = *gpu_args;
  check_resume(dir / "gpu", beam, device, 200, 50, 100);
  check_resume(dir / "gpu_inside", beam, device, 200, 50, 137);
}

TEST(Checkpoint, PathToolResumeContinuesToolsCsv) {
  const fs::path dir = test::test_output_dir("checkpoint_tools");
  const fs::path scene = write_scene(dir, "probe.json", kProbe);
  check_resume(dir, scene, "--threads 1", 60, 20, 40);
  expect_same_file(dir / "full" / "tools.csv", dir / "part" / "tools.csv");
  expect_same_file(dir / "plain" / "tools.csv", dir / "part" / "tools.csv");
  // Cut inside a tool chunk of the uninterrupted run: the chunks after it start elsewhere.
  check_resume(dir / "at37", scene, "--threads 1", 60, 20, 37);
  expect_same_file(dir / "plain" / "tools.csv", dir / "at37" / "part" / "tools.csv");
  const nlohmann::json p = read_json(dir / "plain" / "summary.json");
  const nlohmann::json s = read_json(dir / "part" / "summary.json");
  ASSERT_TRUE(p.contains("tools"));
  EXPECT_EQ(s["tools"], p["tools"]);  // max force, contacts and steps in contact of the whole run
  EXPECT_GT(p["tools"][0]["max_force"].get<double>(), 0.0);

  // A run that went on past its last checkpoint (as one killed there would have): the rows
  // after the checkpoint are dropped and written again, once.
  const Ran r = run(scene, "--threads 1 --steps 50 --out " + (dir / "late").string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const Ran again = run(
      scene, "--threads 1 --steps 40 --checkpoint-every 20 --out " + (dir / "again").string(), dir);
  ASSERT_EQ(again.code, 0) << again.err;
  fs::copy_file(dir / "again" / "checkpoint.phx", dir / "late" / "checkpoint.phx",
                fs::copy_options::overwrite_existing);
  const Ran resumed = run(scene, "--threads 1 --resume " + (dir / "late").string(), dir);
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  expect_same_file(dir / "plain" / "tools.csv", dir / "late" / "tools.csv");
}

TEST(Checkpoint, ScalpelResumeKeepsTheCutsOnTheCpuAndTheGpu) {
  const fs::path dir = test::test_output_dir("checkpoint_scalpel");
  const fs::path scene = write_scene(dir, "scalpel.json", kScalpel);
  check_resume(dir / "cpu", scene, "--threads 1", 200, 50, 100);
  expect_same_file(dir / "cpu" / "plain" / "tools.csv", dir / "cpu" / "part" / "tools.csv");
  const nlohmann::json p = read_json(dir / "cpu" / "plain" / "summary.json");
  const nlohmann::json s = read_json(dir / "cpu" / "part" / "summary.json");
  ASSERT_TRUE(p.contains("cutting"));
  EXPECT_GT(p["cutting"]["severed_pairs"].get<int>(), 0);
  EXPECT_EQ(s["cutting"], p["cutting"]);
  EXPECT_EQ(s["tools"], p["tools"]);
  // The checkpoint at step 100 already holds cuts and the cutting force's statistics.
  const Checkpoint at_100 = read_checkpoint(dir / "cpu" / "full" / kCheckpointFile);
  EXPECT_GT(at_100.severed.size(), 0u);
  ASSERT_EQ(at_100.tool_stats.size(), 1u);
  EXPECT_GT(at_100.tool_stats[0].max_feedback, 0.0);
  EXPECT_GT(at_100.tool_stats[0].max_friction, 0.0);
  EXPECT_GT(at_100.tool_stats[0].max_depth, 0.0);
  // ... and the sides the blade keeps the phyxels its body pushed across its plane on.
  ASSERT_EQ(at_100.blade_sides.size(), 1u);
  EXPECT_GT(at_100.blade_sides[0].size(), 0u);
  for (const BladeSide& b : at_100.blade_sides[0])  // with the plane learned on (normal +y)
    EXPECT_GT(std::abs(unpack_side_normal(b.normal).y()), 0.9999) << "phyxel " << b.phyxel;
  // ... and the blade's cutting state (docs/cutting.md, "Rupture and the cutting state"): at the
  // end, out of the block, it has left it; at step 100 it was cutting, and the run resumed there
  // without it pressed without cutting until a new rupture and parted from the plain one.
  EXPECT_EQ(at_100.blades_cutting, std::vector<uint8_t>{0});
  std::string why;
  const std::optional<std::string> gpu_args = gpu_device_args(why);
  if (!gpu_args) GTEST_SKIP() << why;
  const std::string& device = *gpu_args;
  check_resume(dir / "gpu", scene, device, 200, 50, 100);
  check_resume(dir / "gpu_inside", scene, device, 200, 50, 77);
}

// A checkpoint inside a grasper's grip holds the grip (the held phyxels and their offsets):
// the resumed run holds and lets go as the uninterrupted one, bit for bit.
TEST(Checkpoint, GrasperResumeKeepsTheGripOnTheCpuAndTheGpu) {
  const fs::path dir = test::test_output_dir("checkpoint_grasper");
  const fs::path scene = write_scene(dir, "grasper.json", kGrasper);
  check_resume(dir / "cpu", scene, "--threads 1", 60, 20, 20);
  expect_same_file(dir / "cpu" / "plain" / "tools.csv", dir / "cpu" / "part" / "tools.csv");
  const nlohmann::json p = read_json(dir / "cpu" / "plain" / "summary.json");
  const nlohmann::json s = read_json(dir / "cpu" / "part" / "summary.json");
  EXPECT_EQ(s["tools"], p["tools"]);
  EXPECT_GT(p["tools"][0]["max_held"].get<int>(), 0);
  const Ran r = run(
      scene, "--threads 1 --steps 20 --checkpoint-every 20 --out " + (dir / "at_20").string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const Checkpoint at_20 = read_checkpoint(dir / "at_20" / kCheckpointFile);
  ASSERT_EQ(at_20.grips.size(), 1u);
  EXPECT_TRUE(at_20.grips[0].closed);
  EXPECT_FALSE(at_20.grips[0].held.empty());
  check_resume(dir / "cpu_inside", scene, "--threads 1", 60, 20, 27);
  std::string why;
  const std::optional<std::string> gpu_args = gpu_device_args(why);
  if (!gpu_args) GTEST_SKIP() << why;
  const std::string& device = *gpu_args;
  check_resume(dir / "gpu", scene, device, 60, 20, 20);
  check_resume(dir / "gpu_inside", scene, device, 60, 20, 27);
}

// A valid checkpoint to corrupt: the probe scene at step 20.
fs::path good_checkpoint(const fs::path& dir, fs::path& scene) {
  scene = write_scene(dir, "probe.json", kProbe);
  const Ran r = run(
      scene, "--threads 1 --steps 20 --checkpoint-every 20 --out " + (dir / "ok").string(), dir);
  EXPECT_EQ(r.code, 0) << r.err;
  return dir / "ok";
}

// Copies the run folder `from` to `to` with its checkpoint replaced by `bytes`; resumes it.
Ran resume_with(const fs::path& scene, const fs::path& from, const fs::path& to,
                const std::string& bytes) {
  fs::remove_all(to);
  fs::copy(from, to, fs::copy_options::recursive);
  write_bytes(to / kCheckpointFile, bytes);
  return run(scene, "--threads 1 --resume " + to.string(), to.parent_path());
}

TEST(Checkpoint, CorruptFilesAreRefused) {
  const fs::path dir = test::test_output_dir("checkpoint_refused");
  fs::path scene;
  const fs::path ok = good_checkpoint(dir, scene);
  const std::string bytes = read_text(ok / kCheckpointFile);
  ASSERT_GT(bytes.size(), 100u);

  // Truncated: anywhere, including inside the header.
  for (const size_t keep : {size_t(0), size_t(10), bytes.size() / 2, bytes.size() - 1}) {
    const Ran r = resume_with(scene, ok, dir / "cut", bytes.substr(0, keep));
    EXPECT_EQ(r.code, 1) << keep;
    EXPECT_NE(r.err.find("truncated"), std::string::npos) << keep << ": " << r.err;
  }
  // One bit flipped: in the first section, in the middle, in the checksum.
  for (const size_t at : {size_t(40), bytes.size() / 2, bytes.size() - 3}) {
    std::string flipped = bytes;
    flipped[at] = static_cast<char>(flipped[at] ^ 0x10);
    const Ran r = resume_with(scene, ok, dir / "flip", flipped);
    EXPECT_EQ(r.code, 1) << at;
    EXPECT_NE(r.err.find("checksum mismatch"), std::string::npos) << at << ": " << r.err;
  }
  // Another version of the format (the version field, checksum made right again).
  {
    Checkpoint c = read_checkpoint(ok / kCheckpointFile);
    write_checkpoint(dir / "v.phx", c);
    std::string v = read_text(dir / "v.phx");
    const uint32_t version = kCheckpointVersion + 1;
    std::memcpy(v.data() + 8, &version, sizeof version);
    const uint64_t sum = fnv1a64(v.data(), v.size() - 8);
    std::memcpy(v.data() + v.size() - 8, &sum, sizeof sum);
    const Ran r = resume_with(scene, ok, dir / "version", v);
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("format version " + std::to_string(version)), std::string::npos) << r.err;
  }
  // Not a checkpoint at all.
  {
    const Ran r = resume_with(scene, ok, dir / "magic", std::string(200, 'x'));
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("not a phyxel checkpoint"), std::string::npos) << r.err;
  }
  // No checkpoint in the folder.
  {
    fs::remove_all(dir / "none");
    fs::create_directories(dir / "none");
    const Ran r = run(scene, "--resume " + (dir / "none").string(), dir);
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("no checkpoint there"), std::string::npos) << r.err;
  }
  // The intact file still resumes (the copies above were refused for what was done to them).
  const Ran r = resume_with(scene, ok, dir / "intact", bytes);
  EXPECT_EQ(r.code, 0) << r.err;
}

TEST(Checkpoint, RoundTripsAndFailedWritesLeaveNoTemporary) {
  const fs::path dir = test::test_output_dir("checkpoint_file");
  fs::remove_all(dir);
  fs::create_directories(dir);
  Checkpoint c;
  c.scene_hash = 0x1234;
  c.solver = c.device = "cpu (double)";
  c.step = 7;
  c.displacement = {Vec3(1e-3, -2.5e-310, 3), Vec3(0, 0, -0.0)};  // a subnormal, a -0
  c.velocity = {Vec3(4, 5, 6), Vec3(std::nextafter(1.0, 2.0), 0, 0)};
  c.flags = {1, 0};
  c.awake = {0};
  c.object_below_since = {3};
  c.tool_poses.push_back({Vec3(1, 2, 3), Vec3(0, 0, 1)});
  c.tool_stats.push_back({"probe", Vec3(0.5, 0, 0), 0.75, 3, 4, 5});
  write_checkpoint(dir / kCheckpointFile, c);
  EXPECT_FALSE(fs::exists(dir / "checkpoint.phx.tmp"));
  const Checkpoint r = read_checkpoint(dir / kCheckpointFile);
  EXPECT_EQ(r.step, 7);
  EXPECT_EQ(0, std::memcmp(r.displacement.data(), c.displacement.data(), 2 * sizeof(Vec3)));
  EXPECT_EQ(0, std::memcmp(r.velocity.data(), c.velocity.data(), 2 * sizeof(Vec3)));
  ASSERT_EQ(r.tool_stats.size(), 1u);
  EXPECT_EQ(r.tool_stats[0].name, "probe");
  EXPECT_EQ(r.tool_stats[0].steps_in_contact, 5);
  EXPECT_EQ(r.tool_poses[0].position, Vec3(1, 2, 3));
  EXPECT_EQ(r.flags, c.flags);

  // The rename fails (a folder where the file goes): an error naming it, no temporary left,
  // and the folder in its place untouched.
  const fs::path blocked = dir / "blocked";
  fs::create_directories(blocked / kCheckpointFile);
  try {
    write_checkpoint(blocked / kCheckpointFile, c);
    ADD_FAILURE() << "writing over a folder succeeded";
  } catch (const CheckpointError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot write the checkpoint"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(blocked / "checkpoint.phx.tmp"));
  EXPECT_TRUE(fs::is_directory(blocked / kCheckpointFile));
}

TEST(Checkpoint, AnotherSceneIsRefused) {
  const fs::path dir = test::test_output_dir("checkpoint_other_scene");
  fs::path scene;
  const fs::path ok = good_checkpoint(dir, scene);
  // The same scene with one material value changed, and a different scene altogether.
  std::string changed = kProbe;
  changed.replace(changed.find("\"young\": 1e4"), 12, "\"young\": 2e4");
  const fs::path other = write_scene(dir, "changed.json", changed);
  const std::string before = read_text(ok / "tools.csv");
  for (const fs::path& s : {other, write_scene(dir, "beams.json", kBeams)}) {
    const Ran r = run(s, "--resume " + ok.string(), dir);
    EXPECT_EQ(r.code, 1) << s;
    EXPECT_NE(r.err.find("written for another scene file"), std::string::npos) << r.err;
  }
  EXPECT_EQ(read_text(ok / "tools.csv"), before);  // refused before touching the folder
}

}  // namespace
}  // namespace phyxel
