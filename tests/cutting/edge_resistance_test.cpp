// The edge's resistance (docs/cutting.md, "The edge's resistance"): a blade with a threshold is
// held back by the pairs its edge has passed, feels their force, and severs them once its
// cutting force reaches the threshold (then cuts on while it advances: the cutting state). The
// total does not depend on the spacing; at threshold 0 nothing changes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "engine/solver/cutting.h"
#include "tests/cutting/cutting_fixtures.h"

namespace phyxel {
namespace {

using test::ToolStepper;

// The cutting force of each step of a scalpel crossing the beam (crossing_scalpel: the edge
// enters the beam's side y = 0 at t = 3 ms and moves 1 mm per ms), and the pairs severed by
// then.
struct Crossing {
  std::vector<double> force;
  std::vector<size_t> severed;
  std::vector<Vec3> u;
};

Crossing cross_beam(double threshold, double stiffness, int steps) {
  Scene scene = test::clamped_beam(5e4, 5);
  scene.simulation.gravity = Vec3::Zero();
  scene.tools.push_back(test::crossing_scalpel(0.021, -0.003, 0.016, 0.0, 0.016, threshold));
  scene.tools[0].blade.stiffness = stiffness;
  const PhyxelSet set = sample_scene(scene);
  CpuSolver<double> solver(set, scene.simulation.gravity);
  ToolStepper<double> run(solver, scene.tools, scene.simulation.dt);
  Crossing out;
  for (int k = 0; k < steps; ++k) {
    run.run(1);
    out.force.push_back(edge_force(solver.tool_samples().back().force, Vec3::UnitY()));
    out.severed.push_back(solver.severed_count());
  }
  out.u = solver.displacement();
  return out;
}

double mean(const std::vector<double>& v, size_t from, size_t to) {
  double sum = 0;
  for (size_t k = from; k < to; ++k) sum += v[k];
  return sum / double(to - from);
}

// Below its threshold the blade separates nothing, and the force it feels rises as its edge
// goes in: the pairs it has passed hold it back (before, a blade thinner than the spacing felt
// nothing between the phyxels it touched).
TEST(EdgeResistance, TheForceRisesWithTheEdgesAdvanceAndNothingSeparatesBelowTheThreshold) {
  const Crossing c = cross_beam(100.0, kDefaultEdgeStiffness, 55);  // the edge 2.5 mm in
  EXPECT_EQ(c.severed[44], 0u);  // the front 1.7 mm in: nothing carried past the reach (2 mm)
  // Windows of 0.5 mm of the edge's advance past y = 0.2 mm (the body's front at the side).
  std::vector<double> window;
  for (size_t from = 35; from + 5 <= c.force.size(); from += 5)
    window.push_back(mean(c.force, from, from + 5));
  std::printf("[ resist   ] cutting force per 0.5 mm:");
  for (const double f : window) std::printf(" %.4g", f);
  std::printf(" N\n");
  ASSERT_GE(window.size(), 4u);
  for (size_t k = 1; k < window.size(); ++k) EXPECT_GT(window[k], window[k - 1]) << k;
  EXPECT_GT(window.back(), 1e-3);
  // Without the edge's resistance the blade feels (almost) nothing there.
  const Crossing blunt = cross_beam(100.0, 0.0, 55);
  EXPECT_LT(mean(blunt.force, 35, 55), 0.2 * mean(c.force, 35, 55));
}

// Above it (docs/cutting.md, "Rupture and the cutting state"): nothing separates until the
// cutting force first reaches the threshold, the rupture; from then on the blade cuts in every
// substep while it advances through the tissue, as at threshold 0, and what it feels falls back
// below the threshold (the band it held is cut).
TEST(EdgeResistance, TheTissueRupturesAtTheThresholdAndIsThenCutWhileTheBladeAdvances) {
  const Crossing held = cross_beam(100.0, kDefaultEdgeStiffness, 55);
  const double threshold = 0.5 * *std::max_element(held.force.begin(), held.force.end());
  const Crossing c = cross_beam(threshold, kDefaultEdgeStiffness, 130);
  const size_t rupture =
      size_t(std::find_if(c.severed.begin(), c.severed.end(), [](size_t n) { return n > 0; }) -
             c.severed.begin());
  ASSERT_LT(rupture, 55u);
  for (size_t k = 0; k < rupture; ++k) EXPECT_LT(c.force[k], threshold) << k;
  EXPECT_GE(c.force[rupture], threshold);
  EXPECT_LT(mean(c.force, rupture + 5, c.force.size()), threshold);
  // The cut then runs on as at threshold 0: new pairs in as many steps, the whole crossing cut.
  const Crossing zero = cross_beam(0.0, kDefaultEdgeStiffness, 130);
  auto steps_cutting = [&](const Crossing& x) {
    int n = 0;
    for (size_t k = rupture + 1; k < x.severed.size(); ++k) n += x.severed[k] > x.severed[k - 1];
    return n;
  };
  std::printf("[ resist   ] rupture at step %zu; steps severing after it: %d (threshold 0: %d)\n",
              rupture, steps_cutting(c), steps_cutting(zero));
  EXPECT_GE(10 * steps_cutting(c), 7 * steps_cutting(zero));
  int below = 0;  // severing with the force under the threshold: the cutting state, not bursts
  for (size_t k = rupture + 1; k < c.severed.size(); ++k)
    below += c.severed[k] > c.severed[k - 1] && c.force[k] < threshold;
  EXPECT_GE(below, 5);
  EXPECT_GT(c.severed.back(), 200u);
  EXPECT_GT(double(c.severed.back()), 0.9 * double(zero.severed.back()));
}

// A blade that stops leaves the cutting state: moved on again, it deforms the tissue and cuts
// nothing until its force reaches the threshold once more (a new rupture).
TEST(EdgeResistance, ABladeThatStopsNeedsItsThresholdAgain) {
  const Crossing held = cross_beam(100.0, kDefaultEdgeStiffness, 55);
  const double threshold = 0.5 * *std::max_element(held.force.begin(), held.force.end());
  Scene scene = test::clamped_beam(5e4, 5);
  scene.simulation.gravity = Vec3::Zero();
  ToolDesc blade = test::crossing_scalpel(0.021, -0.003, 0.016, 0.0, 0.016, threshold);
  const Vec3 a = blade.path[0].position, b = blade.path[1].position;
  const Vec3 stop = a + 0.45 * (b - a);  // 4.2 mm into the beam, moving at 1 mm/ms
  blade.path = {{0.0, a, Vec3::UnitZ()},
                {0.0072, stop, Vec3::UnitZ()},
                {0.0172, stop, Vec3::UnitZ()},
                {0.0260, b, Vec3::UnitZ()}};
  scene.tools.push_back(blade);
  const PhyxelSet set = sample_scene(scene);
  CpuSolver<double> solver(set, scene.simulation.gravity);
  ToolStepper<double> run(solver, scene.tools, scene.simulation.dt);
  const int stopped = int(std::ceil(0.0075 / scene.simulation.dt));
  const int moving = int(std::ceil(0.0175 / scene.simulation.dt));
  const int steps = int(std::ceil(0.026 / scene.simulation.dt));
  std::vector<double> force;
  std::vector<size_t> severed;
  for (int k = 0; k < steps; ++k) {
    run.run(1);
    force.push_back(edge_force(solver.tool_samples().back().force, Vec3::UnitY()));
    severed.push_back(solver.severed_count());
    if (k == stopped + 2) {
      EXPECT_FALSE(solver.blade_cutting(0));  // stopped: the state ended
    }
  }
  ASSERT_GT(severed[size_t(stopped)], 0u);  // it ruptured before the stop
  // Moving again: the first step that severs has reached the threshold, after at least one
  // that pressed the tissue without cutting.
  size_t again = size_t(moving);
  while (again < severed.size() && severed[again] == severed[again - 1]) ++again;
  ASSERT_LT(again, severed.size());
  EXPECT_GT(again, size_t(moving));
  EXPECT_GE(force[again], threshold);
  EXPECT_GT(force[again - 1], 0.0);
  EXPECT_LT(force[again - 1], threshold);
  EXPECT_TRUE(solver.blade_cutting(0) || severed.back() > severed[again]);
}

// At threshold 0 the blade cuts whenever it moves through tissue and holds nothing: the edge's
// stiffness changes no bit.
TEST(EdgeResistance, AtThresholdZeroTheStiffnessChangesNothing) {
  const Crossing stiff = cross_beam(0.0, kDefaultEdgeStiffness, 80);
  const Crossing none = cross_beam(0.0, 0.0, 80);
  ASSERT_GT(stiff.severed.back(), 0u);
  EXPECT_EQ(stiff.severed, none.severed);
  EXPECT_EQ(stiff.force, none.force);
  EXPECT_EQ(stiff.u, none.u);
}

// A blade whose force never reaches its threshold (100 N) still severs the pairs its edge
// carries past its reach (edge_passes): it is not a hook that drags a strand of tissue behind
// it. Across the clamped beam (the edge 12 mm along, 1 mm short of the path's end), every
// severed pair crosses the blade's plane at rest, and every crossing pair of the first two
// rows (y <= 2 mm) is severed; without the rule nothing was. (The beam bends ahead of the
// blade, so the rows beyond are carried along, not past the reach.)
TEST(EdgeResistance, APairCarriedPastTheReachIsSeveredWhateverTheForce) {
  Scene scene = test::clamped_beam(5e4, 5);
  scene.simulation.gravity = Vec3::Zero();
  const double x_cut = 0.021, threshold = 100.0;
  scene.tools.push_back(test::crossing_scalpel(x_cut, -0.003, 0.016, 0.0, 0.016, threshold));
  const PhyxelSet set = sample_scene(scene);
  CpuSolver<double> solver(set, scene.simulation.gravity);
  ToolStepper<double> run(solver, scene.tools, scene.simulation.dt);
  double largest = 0;
  for (int k = 0; k < 150; ++k) {
    run.run(1);
    largest = std::max(largest, edge_force(solver.tool_samples().back().force, Vec3::UnitY()));
  }
  std::printf("[ resist   ] largest cutting force %.3g N, %zu pairs severed\n", largest,
              solver.severed_count());
  EXPECT_LT(largest, threshold);
  size_t across = 0;
  std::vector<bool> severed(solver.pair_weights().size(), false);
  const NeighbourLists& nbr = solver.neighbours();
  for (const SeveredPair& p : solver.severed_log()) {
    EXPECT_LT((set.rest[p.i].x() - x_cut) * (set.rest[p.j].x() - x_cut), 0) << p.i << " " << p.j;
    severed[nbr.slot(p.i, p.j)] = true;
  }
  for (uint32_t i = 0; i < set.size(); ++i)
    for (uint32_t k = nbr.offset[i]; k < nbr.offset[i + 1]; ++k) {
      const uint32_t j = nbr.index[k];
      if (j < i || (set.rest[i].x() - x_cut) * (set.rest[j].x() - x_cut) > 0) continue;
      if (std::max(set.rest[i].y(), set.rest[j].y()) > 0.0021) continue;
      ++across;
      EXPECT_TRUE(severed[k]) << i << " " << j << ": " << set.rest[i].transpose() << " / "
                              << set.rest[j].transpose();
    }
  EXPECT_GT(across, 40u);
  EXPECT_GE(solver.severed_count(), across);
}

// The law: pairs crossing the blade's plane behind its front, each pushed with k a_ij delta,
// add up to k L D^2 / 2 for a band of depth D along a blade of length L inside the tissue,
// whatever the spacing (a_ij: the pair's share of the plane's area). Averaged over four
// positions of the front within the coarse spacing (the band's rows of crossings sample it).
double held_force_at_rest(double spacing) {
  Scene scene = test::box_scene(Vec3(0, 0, 0), Vec3(0.02, 0.02, 0.02), spacing, test::tissue(5e4));
  scene.simulation.gravity = Vec3::Zero();
  const PhyxelSet set = sample_scene(scene);
  CpuSolver<double> solver(set, scene.simulation.gravity);
  double sum = 0;
  const int offsets = 4;
  for (int k = 0; k < offsets; ++k) {
    ToolDesc t = test::crossing_scalpel(0.0103, 0.0055, 0.008, 0.0, 1.0, 1e3);
    t.shape.radius = 1e-5;
    t.blade.reach = 0.004;  // the band's depth D
    const Vec3 tip(0.0103, 0.012 + 0.002 * (k + 0.5) / offsets, 0.0055);
    t.path = {{0.0, tip, Vec3::UnitZ()}, {1.0, tip + Vec3(0, 0.001, 0), Vec3::UnitZ()}};
    ToolStepper<double> run(solver, {t}, 1e-5);
    run.run(1);
    EXPECT_EQ(solver.tool_samples().back().contacts, 0u);  // only the held pairs push
    sum += edge_force(solver.tool_samples().back().force, Vec3::UnitY());
  }
  return sum / offsets;
}

TEST(EdgeResistance, TheHeldForceIsTheLawsAtEverySpacing) {
  const double expected = kDefaultEdgeStiffness * 0.008 * 0.004 * 0.004 / 2;
  const double coarse = held_force_at_rest(0.002), fine = held_force_at_rest(0.001);
  std::printf("[ resist   ] held force %.4g N (2 mm), %.4g N (1 mm), law %.4g N\n", coarse, fine,
              expected);
  EXPECT_NEAR(coarse, expected, 0.03 * expected);
  EXPECT_NEAR(fine, expected, 0.03 * expected);
}

// A blade turned about a point of its own moves backwards beyond that point: there the pairs
// behind its own motion hold it, and push the other way. Turned about a point a quarter of its
// length from the tip, three quarters push back along the middle's motion and one quarter
// against it: half the held force of a blade moved straight.
TEST(EdgeResistance, EachPartOfATurnedBladeIsHeldAgainstItsOwnMotion) {
  Scene scene = test::box_scene(Vec3(0, 0, 0), Vec3(0.02, 0.02, 0.02), 0.001, test::tissue(5e4));
  scene.simulation.gravity = Vec3::Zero();
  const PhyxelSet set = sample_scene(scene);
  CpuSolver<double> solver(set, scene.simulation.gravity);
  const double length = 0.008, pivot = 0.25 * length, angle = 1e-3;
  double sum = 0;
  const int offsets = 4;
  for (int k = 0; k < offsets; ++k) {
    const Vec3 centre(0.0103, 0.01 + 0.002 * (k + 0.5) / offsets, 0.0055 + pivot);
    const Vec3 turned(0, std::sin(angle), std::cos(angle));
    ToolDesc t = test::crossing_scalpel(0.0103, 0.0055, length, 0.0, 1.0, 1e3);
    t.shape.radius = 1e-5;
    t.blade.reach = 0.004;
    t.path = {{0.0, centre - pivot * Vec3::UnitZ(), Vec3::UnitZ()},
              {1e-3, centre - pivot * turned, turned}};
    ToolStepper<double> run(solver, {t}, 1e-5);
    run.run(1);
    sum += edge_force(solver.tool_samples().back().force, Vec3::UnitY()) / offsets;
  }
  const double straight = kDefaultEdgeStiffness * length * 0.004 * 0.004 / 2;
  std::printf("[ resist   ] held force of the turned blade %.4g N, of a straight one %.4g N\n", sum,
              straight);
  // The band's depth falls in proportion to the distance from the pivot (D |s| / (3L/4)):
  // k D^2 / 2 times the integral of (s / (3L/4))^2, 1/4 - 1/108 of L along the middle's motion.
  EXPECT_NEAR(sum, (0.25 - 1.0 / 108) * straight, 0.05 * straight);
}

// Where a turned blade pivots it moves nothing and passes nothing: the band that pushes is as
// deep as that point's motion over the faster end's times the reach, as its quad reaches ahead
// (edge_pushes). Before, a pair there pushed one reach deep with the full k a delta, one way on
// the tip's side of the pivot and the other way beyond it: a field with a curl that pumped a
// phyxel beside the pivot through the blade's body and back until it outran sound (the breast's
// turn at K = 2.5, docs/cutting.md "The edge's resistance"). What a separation severs (the held
// band, edge_holds) stays one reach deep: it closes the cone's apex.
TEST(EdgeResistance, ATurnedBladePushesNothingAtItsPivot) {
  EdgeFrame f;
  f.length = 0.08;
  f.front = 0.0006;
  f.depth = 0.0016;
  f.stiffness = kDefaultEdgeStiffness;
  f.tip_motion = -1e-6;  // the pivot 1 cm from the tip
  f.end_motion = 7e-6;
  double t = 0, delta = 0, direction = 0;
  // 1 mm short of the pivot, 0.3 mm behind the axis against the motion there (-x).
  const Vec3 p(3e-4, -5e-4, 0.009), q(3e-4, 5e-4, 0.009);
  EXPECT_FALSE(edge_pushes(p, q, f, &t, &delta, &direction));
  ASSERT_TRUE(edge_holds(p, q, f, &t, &delta, &direction));
  EXPECT_NEAR(delta, 9e-4, 1e-12);
  // At the end, which moves fastest: it pushes the whole reach deep, as before.
  const Vec3 a(-8e-4, -5e-4, 0.079), b(-8e-4, 5e-4, 0.079);
  ASSERT_TRUE(edge_pushes(a, b, f, &t, &delta, &direction));
  EXPECT_NEAR(delta, 1.4e-3, 1e-12);
  EXPECT_EQ(direction, 1.0);
}

// The fastest phyxel (m/s) over `steps` substeps after the first `until` seconds of the tool's
// path.
double fastest_after(const Scene& scene, const ToolDesc& t, const Vec3& gravity, double dt,
                     double until, int steps) {
  const PhyxelSet set = sample_scene(scene);
  CpuSolver<double> solver(set, gravity);
  ToolStepper<double> run(solver, {t}, dt);
  run.run(int64_t(until / dt));
  double fastest = 0;
  for (int k = 0; k < steps; ++k) {
    run.run(1);
    for (const Vec3& v : solver.velocity()) fastest = std::max(fastest, v.norm());
  }
  return fastest;
}

// A blade stabbed in along its axis holds nothing; when it then moves sideways, the pairs
// already behind its edge (up to one reach) are held at once. A phyxel on the blade's plane
// holds about half its pairs, k * 8 V / (3 R) in all (R the support radius): at 1e8 N/m^3 on
// 5 kPa tissue at 3 mm that throws it at omega * delta, faster than sound (4.27 m/s) before
// the pairs fail. Bounded by the threshold (bounded_edge_push), it moves with the tissue.
// Returns the fastest phyxel over the sideways motion (m/s).
double fastest_after_a_stab(double stiffness) {
  Material m = test::tissue(5000, 0.45, 20);
  m.density = 1040;
  Scene scene = test::box_scene(Vec3(0, 0, 0), Vec3(0.04, 0.03, 0.02), 0.003, m);
  scene.objects[0].fixed.push_back(test::box_shape(Vec3(-1, -1, -1), Vec3(1, 1, 0.0015)));
  const double dt = 2.4e-4, speed = 0.15, stab = 0.0768;  // 11.5 mm down, then along +x
  const Vec3 top(0.011, 0.015, 0.021), in = top - speed * stab * Vec3::UnitZ();
  ToolDesc t = test::crossing_scalpel(0.011, 0.021, 0.04, 0.0, 1.0, 0.02);
  t.shape.radius = 0.0004;
  t.blade.length = 0.02;
  t.blade.edge = Vec3::UnitX();
  t.blade.stiffness = stiffness;
  t.path = {{0.0, top, Vec3::UnitZ()},
            {stab, in, Vec3::UnitZ()},
            {stab + 0.015, in + speed * 0.015 * Vec3::UnitX(), Vec3::UnitZ()}};
  return fastest_after(scene, t, Vec3::Zero(), dt, stab, 60);
}

TEST(EdgeResistance, ABladeMovedSidewaysAfterAStabDoesNotThrowTheTissue) {
  const double fastest = fastest_after_a_stab(1e8), p_wave = 4.27;
  std::printf("[ resist   ] fastest phyxel after the stab, 1e8 N/m^3: %.3g m/s\n", fastest);
  EXPECT_TRUE(std::isfinite(fastest));
  EXPECT_LT(fastest, 0.25 * p_wave);
}

// The breast's stab and the start of its turn (scenes/breast_resection.json, K = 2.5: spacing
// 1.6 mm, a substep of 7.667e-5 s, 0.06 N) in a block of its tissue around the cone's apex: the
// blade goes in along its axis, then turns about the apex, 1 cm from its tip in the fixed base.
// Returns the fastest phyxel over the turn's first `steps` substeps (m/s).
double fastest_in_the_turn(int steps) {
  Material m = test::tissue(6000, 0.45, 40);
  m.density = 980;
  Scene scene = test::box_scene(Vec3(0.0016, 0.0016, 0), Vec3(0.0192, 0.0192, 0.0128), 0.0016, m);
  scene.objects[0].fixed.push_back(test::box_shape(Vec3(-1, -1, -1), Vec3(1, 1, 0.0005)));
  const double dt = 7.667e-5, stab = 0.1124;  // settled 0.03 s, then 22 mm in at 0.267 m/s
  const Vec3 apex(0.01, 0.01, 0.00408), axis(0, 0.573576, 0.819152);
  const Vec3 tip = apex - 0.01 * axis;
  ToolDesc t = test::crossing_scalpel(0.01, 0.0, 0.085, 0.0, 1.0, 0.06);
  t.shape.radius = 0.0006;
  t.blade.edge = Vec3(-1, 0, 0);
  t.blade.reference_axis = axis;
  t.path = {{0.0, tip + 0.022 * axis, axis}, {0.03, tip + 0.022 * axis, axis}, {stab, tip, axis}};
  for (int k = 1; k <= 2; ++k) {  // the scene's first two keys of the turn, every 0.05 s
    const double a = 0.2618 * k;  // 15 degrees about z through the apex
    const Vec3 turned(-0.573576 * std::sin(a), 0.573576 * std::cos(a), 0.819152);
    t.path.push_back({stab + 0.05 * k, apex - 0.01 * turned, turned});
  }
  return fastest_after(scene, t, Vec3(0, 0, -9.81), dt, stab, steps);
}

TEST(EdgeResistance, TheBreastsTurnAtItsApexDoesNotThrowTheTissue) {
  const double fastest = fastest_in_the_turn(400), p_wave = 4.82;
  std::printf("[ resist   ] fastest phyxel in the turn: %.3g m/s\n", fastest);
  EXPECT_TRUE(std::isfinite(fastest));
  EXPECT_LT(fastest, 0.25 * p_wave);
}

}  // namespace
}  // namespace phyxel
