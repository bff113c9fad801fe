// The SCNI band round a blade's cut on the CPU solver (docs/cutting.md, "Stiffness of a cut
// body"): which phyxels it takes, that its forces are its energy's gradient, that a scene
// without cut_band has none, and that checkpoints keep it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <random>

#include "engine/run/checkpoint.h"
#include "engine/run/simulation.h"
#include "tests/cutting/cutting_fixtures.h"

namespace phyxel {
namespace {

using namespace test;
namespace fs = std::filesystem;

// The clamped beam with a half-depth slit in the plane x = 9 mm (half-way between lattice
// planes), its front at z = 5 mm; cut at rest, then the blade is taken away.
struct SlitBeam {
  Scene scene;
  PhyxelSet set;
  CpuSolver<double> solver;
  explicit SlitBeam(double cut_band)
      : scene(make(cut_band)), set(sample_scene(scene)), solver(set, Vec3::Zero()) {
    ToolStepper<double> run(solver, scene.tools, scene.simulation.dt);
    run.run(200);
    solver.set_tools({});
  }
  static Scene make(double cut_band) {
    Scene s = clamped_beam(5e4, 40);
    s.objects[0].cut_band = cut_band;
    s.tools.push_back(crossing_scalpel(0.009, 0.005, 0.008, 0.0, 0.016));
    return s;
  }
};

// Cut once per binary; each test works on a copy.
const SlitBeam& cut_beam(bool band) {
  if (band) {
    static const SlitBeam with(3);
    return with;
  }
  static const SlitBeam without(0);
  return without;
}

TEST(ScniBand, TakesThePhyxelsWithinItsWidthOfTheCutAndEveryOneWithACutPair) {
  const SlitBeam& beam = cut_beam(true);
  const CpuSolver<double>& solver = beam.solver;
  ASSERT_GT(solver.severed_count(), 0u);
  ASSERT_FALSE(solver.cut_quads().empty());
  const double width = 3 * 0.002;
  size_t inside = 0;
  for (size_t i = 0; i < beam.set.size(); ++i) {
    const Vec3& x = beam.set.rest[i];
    // The slit: x = 9 mm, z above 5 mm, across the whole beam in y.
    const double d = std::hypot(x.x() - 0.009, std::max(0.0, 0.005 - x.z()));
    EXPECT_EQ(solver.in_band(i), d < width) << "phyxel " << i << " at distance " << d;
    inside += d < width;
  }
  EXPECT_EQ(solver.band_size(), inside);
  for (const SeveredPair& p : solver.severed_log()) {
    EXPECT_TRUE(solver.in_band(p.i)) << p.i;
    EXPECT_TRUE(solver.in_band(p.j)) << p.j;
  }
}

TEST(ScniBand, ItsForcesAreTheGradientOfItsEnergy) {
  SlitBeam beam = cut_beam(true);
  CpuSolver<double>& solver = beam.solver;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> small(-2e-4, 2e-4);
  for (size_t i = 0; i < beam.set.size(); ++i)
    if (!(beam.set.flags[i] & kFixed))
      solver.displacement()[i] = Vec3(small(rng), small(rng), small(rng));
  solver.compute_forces();
  double worst = 0, scale = 0;
  int checked = 0;
  for (size_t i = 0; i < beam.set.size() && checked < 12; ++i) {
    if (!solver.in_band(i) || (beam.set.flags[i] & kFixed) || i % 5) continue;
    ++checked;
    for (int a = 0; a < 3; ++a) {
      const double h = 1e-7, u0 = solver.displacement()[i][a];
      solver.displacement()[i][a] = u0 + h;
      const double up = solver.internal_energy();
      solver.displacement()[i][a] = u0 - h;
      const double down = solver.internal_energy();
      solver.displacement()[i][a] = u0;
      const double expected = -(up - down) / (2 * h);
      worst = std::max(worst, std::abs(solver.force()[i][a] - expected));
      scale = std::max(scale, std::abs(expected));
    }
  }
  ASSERT_GT(checked, 5);
  ASSERT_GT(scale, 0);
  EXPECT_LT(worst, 1e-6 * scale) << "largest force " << scale;
}

TEST(ScniBand, KeepsTheMarginOfTheCourantRule) {
  // The stable step (courant x spacing / p-wave speed) is planned before any cut; the band's
  // sub-box strains must not make the cut body stiffer than it allows.
  SlitBeam band = cut_beam(true), nodal = cut_beam(false);
  const double rule = plan_time_step(band.scene, band.set).dt_stable;
  const double with_band = 2 / max_angular_frequency(band.solver, band.set);
  const double without = 2 / max_angular_frequency(nodal.solver, nodal.set);
  std::printf("[ band     ] stable limit with the band %.4g s, nodal %.4g s, rule %.4g s\n",
              with_band, without, rule);
  EXPECT_LT(rule, 0.9 * with_band) << "limit " << with_band << ", nodal " << without;
}

TEST(ScniBand, AScalpelCutWithoutCutBandKeepsNoBand) {
  const SlitBeam& beam = cut_beam(false);
  EXPECT_GT(beam.solver.severed_count(), 0u);
  EXPECT_TRUE(beam.solver.cut_quads().empty());
  EXPECT_EQ(beam.solver.band_size(), 0u);
  for (size_t i = 0; i < beam.set.size(); ++i) ASSERT_FALSE(beam.solver.in_band(i));
}

TEST(ScniBand, ARunCheckpointedMidCutResumesBitIdentically) {
  // The checkpoint keeps the band (its quads, counts and cells, built or not): a run stopped
  // while the blade is in the slit and resumed ends as the uninterrupted one, bit for bit.
  const Scene scene = SlitBeam::make(3);
  const PhyxelSet set = sample_scene(scene);
  // Chunks of 16 substeps, stopped at 144: the cells of the slit's first 2 mm built, the blade
  // 11 mm along its 16 mm path (0.1 mm a substep).
  const int64_t chunk = 16, stop = 144, total = 240;
  ASSERT_EQ(plan_time_step(scene, set).substeps, 1);
  const fs::path dir = test_output_dir("scni_band_checkpoint");
  auto run = [&](const std::string& name, int64_t steps, const Checkpoint* from) {
    const std::unique_ptr<Solver> solver = make_cpu_solver(set, scene.simulation.gravity, 1);
    RunOptions options;
    options.steps = steps;
    options.tool_chunk_substeps = chunk;
    options.out_dir = dir / name;
    fs::create_directories(options.out_dir);
    options.checkpoint_every = stop;
    options.resume = from;
    options.scene_hash = 0;  // a scene built in code
    run_simulation(scene, set, *solver, options);
    return solver->read_state(false);
  };
  const PointState full = run("full", total, nullptr);
  run("part", stop, nullptr);
  const Checkpoint at_stop = read_checkpoint(dir / "part" / kCheckpointFile);
  const CutBandState& band = at_stop.band;
  ASSERT_FALSE(band.quads.empty());
  ASSERT_GT(std::count_if(band.built_with.begin(), band.built_with.end(),
                          [](uint64_t q) { return q > 0; }),
            0);
  EXPECT_LT(band.quads_before_chunk, band.quads.size());  // the blade still in the slit
  const PointState resumed = run("part", total, &at_stop);
  ASSERT_EQ(resumed.displacement.size(), full.displacement.size());
  for (size_t i = 0; i < full.displacement.size(); ++i) {
    ASSERT_EQ(resumed.displacement[i], full.displacement[i]) << "phyxel " << i;
    ASSERT_EQ(resumed.velocity[i], full.velocity[i]) << "phyxel " << i;
  }
}

}  // namespace
}  // namespace phyxel
