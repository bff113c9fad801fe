// The SCNI band round a blade's cut on the GPU against the CPU reference
// (engine/solver/cpu_solver_band.cpp, compute/gpu_solver_band.cpp): a clamped beam slit
// half-way through at rest (the band built chunk by chunk as the run loop gives the motions,
// then all of it when the blade is taken away), then left to sag under gravity: the same
// band, displacements and strain energy, and a band that matters; checkpoints keep it.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "engine/run/checkpoint.h"
#include "engine/surgery/tool_track.h"
#include "tests/cutting/cutting_fixtures.h"
#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

using phyxel::test::clamped_beam;
using phyxel::test::crossing_scalpel;
namespace fs = std::filesystem;

// The slit: the plane x = 9 mm above z = 5 mm, across the beam in y.
Scene slit_beam(double cut_band) {
  Scene s = clamped_beam(5e4, 40);
  s.objects[0].cut_band = cut_band;
  s.tools.push_back(crossing_scalpel(0.009, 0.005, 0.008, 0.0, 0.016));
  return s;
}

// Cut (200 substeps in chunks of 16), blade taken away, then `after` substeps loaded.
std::vector<Vec3> cut_then_sag(Solver& solver, const Scene& scene, int64_t after) {
  ToolTrack track(scene.tools, {});
  Tools& tools = *solver.tools();
  tools.set_tools(contact_tools(scene.tools));
  const double dt = scene.simulation.dt;
  for (int64_t s = 0; s < 200; s += 16) {
    tools.set_tool_motion(track.motions(s, 16, dt));
    solver.advance(16, dt);
  }
  tools.set_tools({});
  solver.advance(after, dt);
  return solver.read_state(false).displacement;
}

// The largest downward displacement (the tip's, of a clamped beam sagging).
double sag(const std::vector<Vec3>& u) {
  double m = 0;
  for (const Vec3& x : u) m = std::max(m, -x.z());
  return m;
}

TEST_F(GpuSolverTest, TheCutBandMatchesTheCpuAndStiffensTheSlitBeam) {
  const Scene scene = slit_beam(3);
  const PhyxelSet set = sample_scene(scene);
  GpuSolver gpu(ctx(), set, scene.simulation.gravity);
  const std::vector<Vec3> g = cut_then_sag(gpu, scene, 300);
  auto cpu = make_cpu_solver(set, scene.simulation.gravity, 1, true);  // float, as the GPU
  const std::vector<Vec3> c = cut_then_sag(*cpu, scene, 300);
  // The nodal scheme alone (no band): the slit beam sags further.
  const Scene nodal_scene = slit_beam(0);
  auto nodal = make_cpu_solver(sample_scene(nodal_scene), nodal_scene.simulation.gravity, 1, true);
  const std::vector<Vec3> n = cut_then_sag(*nodal, nodal_scene, 300);
  ASSERT_GT(gpu.severed_pairs(), 0u);
  ASSERT_FALSE(gpu.cut_quads().empty());
  // The band's phyxels: those within 3 spacings of the slit, as on the CPU (ScniBand tests).
  size_t inside = 0;
  for (size_t i = 0; i < set.size(); ++i) {
    const Vec3& x = set.rest[i];
    const double d = std::hypot(x.x() - 0.009, std::max(0.0, 0.005 - x.z()));
    EXPECT_EQ(gpu.in_band(i), d < 3 * 0.002) << "phyxel " << i << " at distance " << d;
    inside += d < 3 * 0.002;
  }
  EXPECT_EQ(gpu.band_size(), inside);
  const double tip = sag(c), gap = max_difference(c, g), band_effect = max_difference(c, n);
  std::printf(
      "[ band     ] tip sag: cpu %.6e m, gpu %.6e m, nodal %.6e m; max |u_gpu - u_cpu| "
      "%.3g m, band against nodal %.3g m\n",
      tip, sag(g), sag(n), gap, band_effect);
  EXPECT_GT(tip, 1e-4);
  EXPECT_LT(gap, 1e-4 * tip);
  // A GPU that ignored the band would be as far from the CPU as the nodal scheme is.
  EXPECT_GT(band_effect, 100 * 1e-4 * tip);
  EXPECT_GT(sag(n), sag(c));
  // The strain energy counts the band's boxes on both (a band phyxel's nodal energy is 0).
  const double strain_cpu = cpu->energies().strain, strain_gpu = gpu.energies().strain;
  std::printf("[ band     ] strain energy: cpu %.6e J, gpu %.6e J\n", strain_cpu, strain_gpu);
  EXPECT_GT(strain_cpu, 0);
  EXPECT_NEAR(strain_gpu, strain_cpu, 1e-4 * strain_cpu);
}

TEST_F(GpuSolverTest, ARunWithTheCutBandCheckpointedMidCutResumesBitIdentically) {
  // As ScniBand.ARunCheckpointedMidCutResumesBitIdentically on the CPU: stopped at substep 144
  // of chunks of 16 (cells built, the blade still in the slit), resumed, the same bits.
  const Scene scene = slit_beam(3);
  const PhyxelSet set = sample_scene(scene);
  const fs::path dir = phyxel::test::test_output_dir("gpu_band_checkpoint");
  auto run = [&](const std::string& name, int64_t steps, const Checkpoint* from) {
    GpuSolver gpu(ctx(), set, scene.simulation.gravity);
    RunOptions options;
    options.steps = steps;
    options.tool_chunk_substeps = 16;
    options.out_dir = dir / name;
    fs::create_directories(options.out_dir);
    options.checkpoint_every = 144;
    options.resume = from;
    options.scene_hash = 0;  // a scene built in code
    run_simulation(scene, set, gpu, options);
    return gpu.read_state(false);
  };
  const PointState full = run("full", 240, nullptr);
  run("part", 144, nullptr);
  const Checkpoint at_stop = read_checkpoint(dir / "part" / kCheckpointFile);
  ASSERT_FALSE(at_stop.band.quads.empty());
  ASSERT_GT(std::count_if(at_stop.band.built_with.begin(), at_stop.band.built_with.end(),
                          [](uint64_t q) { return q > 0; }),
            0);
  const PointState resumed = run("part", 240, &at_stop);
  ASSERT_EQ(resumed.displacement.size(), full.displacement.size());
  for (size_t i = 0; i < full.displacement.size(); ++i) {
    ASSERT_EQ(resumed.displacement[i], full.displacement[i]) << "phyxel " << i;
    ASSERT_EQ(resumed.velocity[i], full.velocity[i]) << "phyxel " << i;
  }
}

}  // namespace
}  // namespace phyxel::gpu::test
