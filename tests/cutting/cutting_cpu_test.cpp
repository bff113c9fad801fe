// Cutting on the CPU reference: the visibility criterion, separation of a beam, a slit, the
// force threshold, energy after a cut, and degenerate cuts (engine/solver/cutting.h).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "cutting_fixtures.h"
#include "engine/solver/cutting.h"

namespace phyxel {
namespace {

using test::clamped_beam;
using test::crossing_scalpel;
using test::ToolStepper;

const std::array<Vec3, 4> kUnitQuad = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};

TEST(CutCrossing, ASegmentThroughTheQuadCrossesItAtTheRightFraction) {
  double t = -1;
  EXPECT_TRUE(segment_crosses_quad<double>(Vec3(0.3, 0.6, -1), Vec3(0.3, 0.6, 3), kUnitQuad, &t));
  EXPECT_DOUBLE_EQ(t, 0.25);
  EXPECT_TRUE(segment_crosses_quad<double>(Vec3(0.8, 0.2, 1), Vec3(0.8, 0.2, -1), kUnitQuad, &t));
  EXPECT_DOUBLE_EQ(t, 0.5);
  // Beside the quad, or on one side of it.
  EXPECT_FALSE(segment_crosses_quad<double>(Vec3(1.2, 0.5, -1), Vec3(1.2, 0.5, 1), kUnitQuad));
  EXPECT_FALSE(segment_crosses_quad<double>(Vec3(0.5, 0.5, 0.1), Vec3(0.5, 0.5, 2), kUnitQuad));
}

TEST(CutCrossing, TheTieRulePutsPointsOnThePlaneOnThePositiveSide) {
  // Normal +z: an endpoint at z = 0 is on the positive side, so only a segment going below
  // the plane from it crosses.
  EXPECT_FALSE(segment_crosses_quad<double>(Vec3(0.5, 0.5, 0), Vec3(0.5, 0.5, 1), kUnitQuad));
  EXPECT_TRUE(segment_crosses_quad<double>(Vec3(0.5, 0.5, 0), Vec3(0.5, 0.5, -1), kUnitQuad));
  // Through the shared diagonal, through an outer edge, through a corner: crosses.
  EXPECT_TRUE(segment_crosses_quad<double>(Vec3(0.5, 0.5, 1), Vec3(0.5, 0.5, -1), kUnitQuad));
  EXPECT_TRUE(segment_crosses_quad<double>(Vec3(1, 0.5, 1), Vec3(1, 0.5, -1), kUnitQuad));
  EXPECT_TRUE(segment_crosses_quad<double>(Vec3(0, 0, 1), Vec3(0, 0, -1), kUnitQuad));
  // A still blade sweeps nothing.
  const std::array<Vec3, 4> flat = {Vec3(0, 0, 0), Vec3(0, 0, 1), Vec3(0, 0, 1), Vec3(0, 0, 0)};
  EXPECT_FALSE(segment_crosses_quad<double>(Vec3(-1, 0, 0.5), Vec3(1, 0, 0.5), flat));
}

TEST(CutCrossing, APairThroughTheBladesFrontIsNotSevered) {
  // kUnitQuad's front (the line its tip swept) is p0 -> p3, x = 0: a segment through it passes
  // the crack's edge. The tie rule alone made it cross.
  const Vec3 below(-1, 0.3, -1), above(1, 0.3, 1);  // through (0, 0.3, 0)
  EXPECT_TRUE(segment_crosses_quad<double>(below, above, kUnitQuad));
  EXPECT_FALSE(blade_severs<double>(below, above, kUnitQuad));
  EXPECT_FALSE(blade_severs<double>(above, below, kUnitQuad));
  const Vec3 eps(0.5 * kCutTieTolerance, 0, 0), past(4 * kCutTieTolerance, 0, 0);
  EXPECT_FALSE(blade_severs<double>(below + eps, above + eps, kUnitQuad));  // within the band
  double t = -1;
  EXPECT_TRUE(blade_severs<double>(below + past, above + past, kUnitQuad, &t));
  EXPECT_NEAR(t, 0.5, 1e-9);
  // The quad's other edges and its diagonal keep the tie rule; a segment beside it still misses.
  EXPECT_TRUE(blade_severs<double>(Vec3(1, 0.5, 1), Vec3(1, 0.5, -1), kUnitQuad));
  EXPECT_TRUE(blade_severs<double>(Vec3(0.5, 0, 1), Vec3(0.5, 0, -1), kUnitQuad));
  EXPECT_TRUE(blade_severs<double>(Vec3(0.5, 0.5, 1), Vec3(0.5, 0.5, -1), kUnitQuad));
  EXPECT_FALSE(blade_severs<double>(Vec3(-0.2, 0.5, 1), Vec3(-0.2, 0.5, -1), kUnitQuad));
  EXPECT_TRUE(blade_severs<float>(Eigen::Vector3f(1, 0.3f, 1), Eigen::Vector3f(-0.5f, 0.3f, -1),
                                  {Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(1, 0, 0),
                                   Eigen::Vector3f(1, 1, 0), Eigen::Vector3f(0, 1, 0)}));
}

TEST(CutCrossing, FloatAndDoubleAgreeOutsideTheTieBand) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> d(-0.02, 0.02);
  size_t differ = 0, crossing = 0;
  for (int n = 0; n < 200000; ++n) {
    std::array<Vec3, 4> q;
    for (Vec3& c : q) c = Vec3(d(rng), d(rng), d(rng));
    const Vec3 p(d(rng), d(rng), d(rng)), r(d(rng), d(rng), d(rng));
    std::array<Eigen::Vector3f, 4> qf;
    for (int k = 0; k < 4; ++k) qf[k] = q[k].cast<float>();
    const bool hd = segment_crosses_quad<double>(p, r, q);
    const bool hf = segment_crosses_quad<float>(p.cast<float>(), r.cast<float>(), qf);
    crossing += hd;
    if (hd != hf) {
      ++differ;
      EXPECT_LT(crossing_tie_distance(p, r, q), kCutTieTolerance);
    }
  }
  EXPECT_GT(crossing, 1000u);
  EXPECT_LT(differ, 50u);
}

TEST(CutCrossing, TheEdgeTurnsWithTheAxisAndTheQuadReachesAheadOfIt) {
  Blade b;
  b.length = 0.01;
  b.edge = Vec3::UnitY();
  b.reference_axis = Vec3::UnitZ();
  EXPECT_TRUE(blade_edge(b, {Vec3::Zero(), Vec3::UnitX()}).isApprox(Vec3::UnitY()));
  EXPECT_TRUE(blade_edge(b, {Vec3::Zero(), Vec3::UnitY()}).isApprox(-Vec3::UnitZ()));
  const CutQuad q =
      swept_quad(b, {Vec3::Zero(), Vec3::UnitZ()}, {Vec3(0, 0.001, 0), Vec3::UnitZ()}, 0.002);
  EXPECT_TRUE(q.corner[1].isApprox(Vec3(0, 0, 0.01)));
  EXPECT_TRUE(q.corner[2].isApprox(Vec3(0, 0.003, 0.01)));
  EXPECT_TRUE(q.corner[3].isApprox(Vec3(0, 0.003, 0)));
  EXPECT_DOUBLE_EQ(edge_force(Vec3(0, -2, 1), Vec3::UnitY()), 2.0);
  EXPECT_DOUBLE_EQ(edge_force(Vec3(0, 2, 1), Vec3::UnitY()), 0.0);
  // The cutting force: the edge pushed back (-y here), or the point (the tissue pushing the
  // blade back up its axis, +z), whichever is larger; pulling the blade away cuts nothing.
  EXPECT_DOUBLE_EQ(cut_force(Vec3(0, -2, 1), q), 2.0);
  EXPECT_DOUBLE_EQ(cut_force(Vec3(0, -0.5, 3), q), 3.0);
  EXPECT_DOUBLE_EQ(cut_force(Vec3(0, 1, -1), q), 0.0);
}

// Pairs still joined across the plane x = x_cut (rest positions).
template <class Real>
size_t joined_across(const PhyxelSet& set, const CpuSolver<Real>& s, double x_cut) {
  const NeighbourLists& nbr = s.neighbours();
  size_t joined = 0;
  for (size_t i = 0; i < set.size(); ++i)
    for (uint32_t k = nbr.offset[i]; k < nbr.offset[i + 1]; ++k) {
      const Vec3& a = set.rest[i];
      const Vec3& b = set.rest[nbr.index[k]];
      if ((a.x() - x_cut) * (b.x() - x_cut) < 0 && s.pair_weights()[k] != Real(0)) ++joined;
    }
  return joined;
}

// Mass-weighted centre and velocity of the phyxels with x0 beyond x_cut.
struct Body {
  Vec3 centre = Vec3::Zero(), velocity = Vec3::Zero();
};
Body piece_beyond(const PhyxelSet& set, const CpuSolver<double>& s, double x_cut) {
  Body b;
  double m = 0;
  for (size_t i = 0; i < set.size(); ++i) {
    if (set.rest[i].x() < x_cut) continue;
    m += set.mass[i];
    b.centre += set.mass[i] * (set.rest[i] + s.displacement()[i]);
    b.velocity += set.mass[i] * s.velocity()[i];
  }
  b.centre /= m;
  b.velocity /= m;
  return b;
}

TEST(Cutting, ABeamCutThroughNearItsClampFallsFreely) {
  Scene scene = clamped_beam();
  const double x_cut = 0.009, dt = scene.simulation.dt;
  scene.tools.push_back(crossing_scalpel(x_cut, -0.003, 0.016, 0.0, 0.016));
  const PhyxelSet set = sample_scene(scene);
  CpuSolver<double> solver(set, scene.simulation.gravity);
  ToolStepper<double> run(solver, scene.tools, dt);
  run.run(200);  // the blade has left the beam at t = 16 ms
  EXPECT_EQ(joined_across(set, solver, x_cut), 0u);
  EXPECT_GT(solver.severed_count(), 100u);
  // No force crosses the cut: the piece's momentum changes by gravity alone, so its centre of
  // mass follows x_s + v_s t + g t^2 / 2.
  const Body start = piece_beyond(set, solver, x_cut);
  const double t = 0.1;
  run.run(int64_t(std::lround(t / dt)));
  const Body end = piece_beyond(set, solver, x_cut);
  const Vec3 expected = start.velocity * t + 0.5 * scene.simulation.gravity * t * t;
  const Vec3 moved = end.centre - start.centre;
  EXPECT_NEAR(moved.z(), expected.z(), 0.01 * std::abs(expected.z()));
  EXPECT_NEAR((moved - expected).norm(), 0.0, 0.01 * expected.norm());
  EXPECT_EQ(solver.first_non_finite(), -1);
}

TEST(Cutting, BelowTheForceThresholdTheBladeOnlyPushes) {
  Scene scene = clamped_beam(5e4, 0);
  scene.simulation.gravity = Vec3::Zero();
  // The blade presses the beam's side with well under 1 N: nothing separates.
  scene.tools.push_back(crossing_scalpel(0.02, -0.003, 0.016, 0.0, 0.016, 1.0));
  scene.tools[0].path[1].position.y() = 0.001;  // 1 mm into the side
  const PhyxelSet set = sample_scene(scene);
  CpuSolver<double> solver(set, scene.simulation.gravity);
  ToolStepper<double> run(solver, scene.tools, scene.simulation.dt);
  double felt = 0;
  for (int k = 0; k < 300; ++k) {
    run.run(1);
    for (const ToolContactSample& s : solver.tool_samples()) felt = std::max(felt, s.force.norm());
  }
  EXPECT_GT(felt, 0.0);  // it touched
  EXPECT_LT(felt, 1.0);
  EXPECT_EQ(solver.severed_count(), 0u);
  // The same press with a threshold below what it feels cuts.
  scene.tools[0].blade.threshold = 0.1 * felt;
  CpuSolver<double> sharp(set, scene.simulation.gravity);
  ToolStepper<double> run_sharp(sharp, scene.tools, scene.simulation.dt);
  run_sharp.run(300);
  EXPECT_GT(sharp.severed_count(), 0u);
}

double tip_deflection(const PhyxelSet& set, const CpuSolver<double>& s) {
  double sum = 0;
  int n = 0;
  for (size_t i = 0; i < set.size(); ++i)
    if (set.rest[i].x() > 0.039) {
      sum += s.displacement()[i].z();
      ++n;
    }
  return sum / n;
}

TEST(Cutting, AHalfDepthSlitSoftensTheBeamAndClosesWhenUnloaded) {
  // Damped so that it settles; the slit is cut from the top down to mid-depth before loading.
  Scene scene = clamped_beam(5e4, 40);
  scene.simulation.gravity = Vec3::Zero();
  const double x_cut = 0.009, dt = scene.simulation.dt;
  scene.tools.push_back(crossing_scalpel(x_cut, 0.005, 0.008, 0.0, 0.016));
  const PhyxelSet set = sample_scene(scene);
  std::vector<Vec3> load(set.size(), Vec3::Zero());
  for (size_t i = 0; i < set.size(); ++i)
    if (set.rest[i].x() > 0.039) load[i] = Vec3(0, 0, -2e-4);
  auto settle = [&](CpuSolver<double>& s, bool slit) {
    std::vector<ToolDesc> tools;
    if (slit) tools = scene.tools;
    ToolStepper<double> run(s, tools, dt);
    run.run(250);  // the blade passes
    s.set_external_forces(load);
    run.run(3000);
    return tip_deflection(set, s);
  };
  CpuSolver<double> whole(set, Vec3::Zero()), slit(set, Vec3::Zero());
  const double d_whole = settle(whole, false);
  const double d_slit = settle(slit, true);
  EXPECT_GT(slit.severed_count(), 0u);
  EXPECT_LT(d_whole, 0.0);
  EXPECT_LT(d_slit, 1.05 * d_whole);  // at least 5 % more deflection (both negative)
  // Only the upper half is cut: the lower half still joins the pieces.
  const NeighbourLists& nbr = slit.neighbours();
  size_t lower = 0;
  for (size_t i = 0; i < set.size(); ++i)
    for (uint32_t k = nbr.offset[i]; k < nbr.offset[i + 1]; ++k) {
      const Vec3& a = set.rest[i];
      const Vec3& b = set.rest[nbr.index[k]];
      if ((a.x() - x_cut) * (b.x() - x_cut) < 0 && slit.pair_weights()[k] != 0 && a.z() < 0.004 &&
          b.z() < 0.004)
        ++lower;
    }
  EXPECT_GT(lower, 0u);
  // Unloaded, it springs back and the slit's faces meet again.
  slit.set_external_forces(std::vector<Vec3>(set.size(), Vec3::Zero()));
  ToolStepper<double> rest(slit, {}, dt);
  rest.run(4000);
  EXPECT_LT(std::abs(tip_deflection(set, slit)), 0.02 * std::abs(d_slit));
  double worst = 0;
  for (size_t i = 0; i < set.size(); ++i) worst = std::max(worst, slit.displacement()[i].norm());
  EXPECT_LT(worst, 0.05 * 0.002);  // every phyxel within 5 % of a spacing of its rest place
}

TEST(Cutting, ASlitSeversExactlyThePairsCrossingItAboveItsFront) {
  // The slit's plane and its front lie half-way between lattice planes, so the diagonal pairs
  // between the layers above and below the front pass through the front line itself. Rounding
  // used to sever half of them (by phyxel order), softening the cut body (docs/cutting.md,
  // "Stiffness of a cut body"); none is severed now, and every pair crossing above the front is.
  Scene scene = clamped_beam(5e4, 40);
  const double x_cut = 0.009, front = 0.005;
  scene.tools.push_back(crossing_scalpel(x_cut, front, 0.008, 0.0, 0.016));
  const PhyxelSet set = sample_scene(scene);
  CpuSolver<double> solver(set, Vec3::Zero());
  ToolStepper<double> run(solver, scene.tools, scene.simulation.dt);
  run.run(200);
  const NeighbourLists& nbr = solver.neighbours();
  size_t through_front = 0, wrong = 0, severed = 0;
  for (size_t i = 0; i < set.size(); ++i)
    for (uint32_t k = nbr.offset[i]; k < nbr.offset[i + 1]; ++k) {
      const Vec3& a = set.rest[i];
      const Vec3& b = set.rest[nbr.index[k]];
      const bool cut = solver.pair_weights()[k] == 0;
      severed += cut;
      if ((a.x() - x_cut) * (b.x() - x_cut) >= 0) {
        wrong += cut;
        continue;
      }
      const double z = a.z() + (x_cut - a.x()) / (b.x() - a.x()) * (b.z() - a.z());
      if (std::abs(z - front) < 1e-9)
        ++through_front, wrong += cut;
      else
        wrong += cut != (z > front);
    }
  EXPECT_GT(through_front, 0u);
  EXPECT_GT(severed, 0u);
  EXPECT_EQ(wrong, 0u);
}

TEST(Cutting, EnergyDoesNotRiseAfterACutInAnUndampedRun) {
  Scene scene = clamped_beam(5e4, 0);
  const double dt = scene.simulation.dt;
  scene.tools.push_back(crossing_scalpel(0.021, -0.003, 0.016, 0.01, 0.016));
  const PhyxelSet set = sample_scene(scene);
  CpuSolver<double> solver(set, scene.simulation.gravity);
  ToolStepper<double> run(solver, scene.tools, dt);
  run.run(100);  // sagging, before the blade arrives
  const double before = solver.energies().total();
  double highest = before;
  for (int k = 0; k < 60; ++k) {
    run.run(10);
    highest = std::max(highest, solver.energies().total());
  }
  EXPECT_GT(solver.severed_count(), 0u);
  // The drift of the undamped leapfrog over the same time without a cut bounds what is allowed.
  CpuSolver<double> uncut(set, scene.simulation.gravity);
  ToolStepper<double> run_uncut(uncut, {}, dt);
  run_uncut.run(100);
  const double e0 = uncut.energies().total();
  double drift = 0;
  for (int k = 0; k < 60; ++k) {
    run_uncut.run(10);
    drift = std::max(drift, std::abs(uncut.energies().total() - e0));
  }
  const double scale = std::abs(before) + 1e-12;
  EXPECT_LE(highest - before, std::max(2 * drift, 1e-3 * scale))
      << "before " << before << " highest " << highest << " drift " << drift;
}

TEST(Cutting, DegenerateCutsLeaveEveryValueFinite) {
  // A layer one spacing thick, a cut exactly along a lattice plane, and two crossing cuts.
  Scene thin =
      test::box_scene(Vec3(0, 0, 0), Vec3(0.02, 0.01, 0.002), 0.002, test::tissue(5e4, 0.3, 0));
  thin.simulation.dt = 1e-4;
  thin.simulation.gravity = Vec3(0, 0, -9.81);
  thin.objects[0].fixed.push_back(test::box_shape(Vec3(-1, -1, -1), Vec3(0.0005, 1, 1)));
  thin.tools.push_back(crossing_scalpel(0.010, -0.003, 0.016, 0.0, 0.016));  // a lattice plane
  ToolDesc across = crossing_scalpel(0.0, -0.003, 0.016, 0.02, 0.02);
  across.path = {{0.02, Vec3(0.002, 0.005, -0.003), Vec3::UnitZ()},
                 {0.04, Vec3(0.022, 0.005, -0.003), Vec3::UnitZ()}};  // along y = 5 mm
  across.blade.edge = Vec3::UnitX();
  across.name = "second";
  thin.tools.push_back(across);
  SamplingOptions loose;
  loose.require_usable_fit = false;
  const PhyxelSet set = sample_scene(thin, loose);
  CpuSolver<double> solver(set, thin.simulation.gravity);
  ToolStepper<double> run(solver, thin.tools, thin.simulation.dt);
  for (int k = 0; k < 10; ++k) {
    run.run(60);
    ASSERT_EQ(solver.first_non_finite(), -1) << "after " << run.step << " steps";
  }
  EXPECT_GT(solver.severed_count(), 0u);
  // The tie rule puts each phyxel of the plane x = 10 mm on one side (by where it is when the
  // blade passes): none stays joined to both, and nothing off the plane is joined across.
  const NeighbourLists& nbr = solver.neighbours();
  auto side = [&](uint32_t i) {
    const double x = set.rest[i].x();
    return x < 0.010 - 1e-9 ? -1 : x > 0.010 + 1e-9 ? 1 : 0;
  };
  for (uint32_t i = 0; i < set.size(); ++i) {
    bool near = false, far = false;
    for (uint32_t k = nbr.offset[i]; k < nbr.offset[i + 1]; ++k) {
      if (solver.pair_weights()[k] == 0) continue;
      near = near || side(nbr.index[k]) < 0;
      far = far || side(nbr.index[k]) > 0;
    }
    const bool across = side(i) < 0 ? far : side(i) > 0 ? near : (near && far);
    EXPECT_FALSE(across) << "phyxel " << i << " at x0 = " << set.rest[i].x();
  }
  const Energies e = solver.energies();
  EXPECT_TRUE(std::isfinite(e.total()));
}

}  // namespace
}  // namespace phyxel
