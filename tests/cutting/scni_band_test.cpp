// The SCNI band round a blade's cut on the CPU solver (docs/cutting.md, "Stiffness of a cut
// body"): which phyxels it takes, that its forces are its energy's gradient, and that a scene
// without cut_band has none.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "tests/cutting/cutting_fixtures.h"

namespace phyxel {
namespace {

using namespace test;

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

TEST(ScniBand, CheckpointsOfABandSceneAreRefused) {
  // The band's quads are not in checkpoints: a run that would write or resume one stops first.
  const Scene scene = SlitBeam::make(3);
  const PhyxelSet set = sample_scene(scene);
  const std::unique_ptr<Solver> solver = make_cpu_solver(set, scene.simulation.gravity, 1);
  RunOptions options;
  options.steps = 1;
  options.out_dir = test_output_dir("scni_band_checkpoint");
  options.checkpoint_every = 1;
  try {
    run_simulation(scene, set, *solver, options);
    FAIL() << "a checkpointed run of a cut_band scene started";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cut_band: checkpoints do not store"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace phyxel
