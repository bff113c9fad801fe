// One side per phyxel while a blade with a threshold passes (docs/cutting.md, "One side per
// phyxel"): a phyxel on the blade's plane, pushed across it, keeps the pairs of the side it was
// first cut to, so a cut along a lattice plane frees no single phyxels (scenes/scalpel_cut.json
// freed 109).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "engine/solver/contact.h"
#include "engine/solver/cutting.h"
#include "tests/cutting/cutting_fixtures.h"

namespace phyxel {
namespace {

TEST(BladeSide, AnEntryGivesTheSideAtItsPassesStartAndLapsesAfterASubstepWithoutIt) {
  const uint32_t entry = side_entry(7, kSideNone, kSidePlus);
  EXPECT_EQ(side_at_start(entry, 7), kSideNone);  // read during its own pass: the start's
  EXPECT_EQ(side_at_start(entry, 8), kSidePlus);  // the next pass starts with it
  EXPECT_EQ(side_at_start(entry, 9), kSideNone);  // not renewed in pass 8: lapsed
  EXPECT_EQ(side_at_start(side_entry(kSidePassMask, kSideMinus, kSideMinus), 0), kSideMinus);
  EXPECT_EQ(side_after(kSideNone, kSidePlus | kSideMinus), kSideNone);  // cut both ways: none
  EXPECT_EQ(side_after(kSideMinus, kSidePlus), kSideMinus);             // kept
}

TEST(BladeSide, APairIsNotCutFromThePhyxelsKeptSide) {
  const Vec3 n = Vec3::UnitY(), on_plane(0, -1e-9, 0), above(0, 0.002, 0), below(0, -0.002, 0);
  // First cut to +y (its pair to -y severed), then nudged below the plane: its pairs to +y
  // cross the plane now, and are kept.
  EXPECT_EQ(side_from(n, Vec3::Zero(), below), kSidePlus);
  EXPECT_FALSE(sides_allow(kSidePlus, kSideNone, n, on_plane, above));
  EXPECT_TRUE(sides_allow(kSidePlus, kSideNone, n, on_plane, below));
  EXPECT_FALSE(sides_allow(kSideNone, kSidePlus, n, above, on_plane));  // j kept on +y
  EXPECT_TRUE(sides_allow(kSideNone, kSideNone, n, on_plane, above));
}

// A phyxel the blade keeps on +y, on the blade's plane just inside the front of its body: the
// contact moves it out toward +y without friction, not ahead of the blade (the runaway of
// docs/cutting.md, "One side per phyxel"); without a side it goes out radially, ahead.
TEST(BladeSide, AKeptPhyxelLeavesTheBladesBodyTowardItsSide) {
  ContactTool tool;
  tool.shape.type = ToolShape::Type::Capsule;
  tool.shape.radius = 0.0004;
  tool.shape.length = 0.02;
  tool.friction = 0.3;
  ToolMotion m;
  m.from = {Vec3(-0.0001, 0, 0), Vec3::UnitZ()};
  m.to = {Vec3(0, 0, 0), Vec3::UnitZ()};
  const Vec3 x(0.00039, -1e-9, 0.005), v = Vec3::Zero();
  Vec3 dx, dv;
  ASSERT_TRUE(contact_correction<double>(tool, m, 1e-4, x, x, v, dx, dv, Vec3::UnitY()));
  EXPECT_NEAR(dx.x(), 0.0, 1e-12);  // no friction drags it along
  EXPECT_NEAR(dx.y(), std::sqrt(0.0004 * 0.0004 - 0.00039 * 0.00039) + 1e-9, 1e-9);
  ASSERT_TRUE(contact_correction<double>(tool, m, 1e-4, x, x, v, dx, dv));
  EXPECT_GT(dx.x(), 0.0);  // radially: ahead
  EXPECT_LT(std::abs(dx.y()), 1e-8);
  // Beyond the segment (the point's cap) the normal stays radial.
  const Vec3 ahead(0.0001, 0, -0.0001);
  ASSERT_TRUE(contact_correction<double>(tool, m, 1e-4, ahead, ahead, v, dx, dv, Vec3::UnitY()));
  EXPECT_LT(std::abs(dx.y()), 1e-8);
}

// A block like scalpel_cut's (2 mm, 5 kPa, y = 0 a lattice plane) cut along y = 0 by a blade
// with `threshold`: the pairs each phyxel lost, to -y and to +y (by rest positions), and
// those it keeps.
struct PlaneCut {
  PhyxelSet set;
  size_t severed = 0, kept_sides = 0;
  std::vector<int> lost_below, lost_above, live;
};

PlaneCut cut_along_lattice_plane(double threshold) {
  Scene scene = test::box_scene(Vec3(-0.012, -0.006, 0), Vec3(0.012, 0.006, 0.010), 0.002,
                                test::tissue(5000, 0.45, 20));
  scene.objects[0].fixed.push_back(test::box_shape(Vec3(-1, -1, -1), Vec3(1, 1, 0.0015)));
  scene.simulation.dt = 2.4e-4;
  scene.simulation.gravity = Vec3(0, 0, -9.81);
  ToolDesc blade = test::crossing_scalpel(0, 0.004, 0.02, 0.0, 0.16, threshold);
  blade.shape.radius = 0.0004;
  blade.path = {{0.0, Vec3(-0.016, 0, 0.004), Vec3::UnitZ()},
                {0.16, Vec3(0.006, 0, 0.004), Vec3::UnitZ()}};
  blade.blade.edge = Vec3::UnitX();
  scene.tools.push_back(blade);
  PlaneCut out;
  out.set = sample_scene(scene);
  CpuSolver<double> solver(out.set, scene.simulation.gravity);
  test::ToolStepper<double> run(solver, scene.tools, scene.simulation.dt);
  run.run(700);
  EXPECT_EQ(solver.first_non_finite(), -1);
  out.severed = solver.severed_count();
  out.kept_sides = solver.blade_sides(0).size();
  const size_t n = out.set.size();
  out.lost_below.assign(n, 0);
  out.lost_above.assign(n, 0);
  out.live.assign(n, 0);
  const NeighbourLists& nbr = solver.neighbours();
  for (uint32_t i = 0; i < n; ++i)
    for (uint32_t k = nbr.offset[i]; k < nbr.offset[i + 1]; ++k) {
      const double dy = out.set.rest[nbr.index[k]].y() - out.set.rest[i].y();
      if (solver.pair_weights()[k] != 0)
        ++out.live[i];
      else if (std::abs(dy) > 1e-9)  // a pair within the plane joins no side
        ++(dy < 0 ? out.lost_below : out.lost_above)[i];
    }
  return out;
}

void expect_one_side_and_nothing_freed(const PlaneCut& cut) {
  EXPECT_GT(cut.severed, 150u);  // the cut went through
  int on_plane_cut = 0;
  for (uint32_t i = 0; i < cut.set.size(); ++i) {
    EXPECT_GT(cut.live[i], 0) << "phyxel " << i << " at " << cut.set.rest[i].transpose()
                              << " cut free";
    if (std::abs(cut.set.rest[i].y()) > 1e-9) continue;
    if (cut.lost_below[i] + cut.lost_above[i] > 0) ++on_plane_cut;
    EXPECT_FALSE(cut.lost_below[i] > 0 && cut.lost_above[i] > 0)
        << "phyxel " << i << " on the plane at " << cut.set.rest[i].transpose() << " lost "
        << cut.lost_below[i] << " pairs below and " << cut.lost_above[i] << " above";
  }
  EXPECT_GT(on_plane_cut, 20);  // the blade passed along the plane's phyxels
  EXPECT_GT(cut.kept_sides, 0u);
}

TEST(BladeSide, ACutAlongALatticePlaneAboveItsThresholdFreesNoPhyxel) {
  expect_one_side_and_nothing_freed(cut_along_lattice_plane(0.02));
}

// At threshold 0 no side is kept (docs/cutting.md, "One side per phyxel": breast_resection's
// cone, whose blade turns about phyxels that stay candidates, did not close with them).
TEST(BladeSide, AtThresholdZeroNoSideIsKept) {
  const PlaneCut cut = cut_along_lattice_plane(0.0);
  EXPECT_GT(cut.severed, 150u);
  EXPECT_EQ(cut.kept_sides, 0u);
}

// A blade that keeps sides, moved along +x through the same block with its plane tilted (normal
// n = (0, 1, 1) / sqrt 2, through y + z = 4.5 mm), where the phyxels of the lattice's row
// y + z = `row` near its start are kept on the plane's -n side, learned on a plane of normal
// `learned`: a side learned where the blade's plane lay elsewhere (breast_resection's cone turns
// about its apex, whose phyxels stay candidates all the turn; docs/cutting.md, "Stale sides at
// the cone's apex"). Without sides (`learned` null) none is put. The pairs severed, sorted.
std::vector<std::pair<uint32_t, uint32_t>> cut_beside_stale_sides(double row, const Vec3* learned) {
  Scene scene = test::box_scene(Vec3(-0.012, -0.006, 0), Vec3(0.012, 0.006, 0.010), 0.002,
                                test::tissue(5000, 0.45, 20));
  scene.objects[0].fixed.push_back(test::box_shape(Vec3(-1, -1, -1), Vec3(1, 1, 0.0015)));
  scene.simulation.dt = 2.4e-4;
  ToolDesc blade = test::crossing_scalpel(0, 0.004, 0.02, 0.0, 0.16, 0.02);
  blade.shape.radius = 0.0004;
  const Vec3 axis = Vec3(0, -1, 1).normalized();
  blade.path = {{0.0, Vec3(-0.016, 0.003, 0.0015), axis}, {0.16, Vec3(0.006, 0.003, 0.0015), axis}};
  blade.blade.edge = Vec3::UnitX();
  blade.blade.reference_axis = axis;
  scene.tools.push_back(blade);
  const PhyxelSet set = sample_scene(scene);
  CpuSolver<double> solver(set, scene.simulation.gravity);
  test::ToolStepper<double> run(solver, scene.tools, scene.simulation.dt);
  if (learned) {
    std::vector<BladeSide> kept;
    for (uint32_t i = 0; i < set.size(); ++i)
      if (std::abs(set.rest[i].y() + set.rest[i].z() - row) < 1e-9 && set.rest[i].x() < -0.009)
        kept.push_back({i, kSideMinus, pack_side_normal(*learned)});
    EXPECT_GT(kept.size(), 5u);
    solver.restore_blade_sides(0, kept);
  }
  run.run(700);
  EXPECT_EQ(solver.first_non_finite(), -1);
  std::vector<std::pair<uint32_t, uint32_t>> pairs;
  for (const SeveredPair& p : solver.severed_log()) pairs.emplace_back(p.i, p.j);
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

const Vec3 kTiltedNormal = Vec3(0, 1, 1).normalized();  // the blade's of cut_beside_stale_sides

// The row y + z = 8 mm lies 2.47 mm on +n, beyond a spacing: its sides, learned on the blade's
// own plane, have lapsed, and the blade severs its pairs to the row y + z = 4 mm (on -n) as it
// does without those sides.
TEST(BladeSide, ASideKeptBeyondASpacingOnTheOtherSideOfTheBladesPlaneHasLapsed) {
  const std::vector<std::pair<uint32_t, uint32_t>> fresh = cut_beside_stale_sides(0, nullptr);
  EXPECT_GT(fresh.size(), 50u);  // the cut went through
  EXPECT_EQ(cut_beside_stale_sides(0.008, &kTiltedNormal), fresh);
}

// The row y + z = 6 mm lies 1.06 mm on +n, within the band, as breast_resection's phyxel 7 377
// lay 0.62 mm across the cone's plane: kept on -n by the blade's own plane, its sides hold and
// keep its pairs to -n; learned on a plane turned 45 degrees (normal +y), they have lapsed and
// the blade severs as without them.
TEST(BladeSide, ASideLearnedOnATurnedPlaneHasLapsedWithinItsBand) {
  const std::vector<std::pair<uint32_t, uint32_t>> fresh = cut_beside_stale_sides(0, nullptr);
  const std::vector<std::pair<uint32_t, uint32_t>> held =
      cut_beside_stale_sides(0.006, &kTiltedNormal);
  EXPECT_NE(held, fresh);  // the sides hold where they were learned
  const Vec3 turned = Vec3::UnitY();
  EXPECT_EQ(cut_beside_stale_sides(0.006, &turned), fresh);
}

TEST(BladeSide, ASideLapsesOnlyBeyondItsBandOnTheOtherSide) {
  EdgeFrame f;
  f.tip = Vec3(0, 0.001, 0);
  f.normal = Vec3::UnitY();
  const uint32_t here = pack_side_normal(f.normal);
  const double band = side_band(0.0004, 0.002);
  EXPECT_EQ(band, 0.002);
  EXPECT_EQ(side_band(0.0006, 0.0004), 0.0006);
  EXPECT_EQ(side_near_plane(kSidePlus, here, f, Vec3(0, -0.0009, 0), band), kSidePlus);  // 1.9 mm
  EXPECT_EQ(side_near_plane(kSidePlus, here, f, Vec3(0, -0.0011, 0), band), kSideNone);  // 2.1 mm
  EXPECT_EQ(side_near_plane(kSideMinus, here, f, Vec3(0, -0.0011, 0), band), kSideMinus);
  EXPECT_EQ(side_near_plane(kSideMinus, here, f, Vec3(0, 0.0031, 0), band), kSideNone);
  EXPECT_EQ(side_near_plane(kSideNone, here, f, Vec3(0, 0.0031, 0), band), kSideNone);
}

// A side holds while the blade's plane stays within kSideTurn (10 degrees) of the one it was
// learned on, whatever the phyxel's place; a plane turned further, or the blade moving the other
// way (its normal flipped), leaves no side.
TEST(BladeSide, ASideLapsesOnceTheBladesPlaneHasTurnedFromTheOneItWasLearnedOn) {
  for (const Vec3& n : {Vec3(0, 1, 0), Vec3(0.3, -0.5, -0.81), Vec3(-0.7, 0.1, 0.2), Vec3(0, 0, -1),
                        Vec3(0.6, 0.8, 0)}) {
    const Vec3 back = unpack_side_normal(pack_side_normal(n.normalized()));
    EXPECT_NEAR(back.norm(), 1.0, 1e-12);
    EXPECT_LT((back - n.normalized()).norm(), 1e-4) << n.transpose();
  }
  EdgeFrame f;
  f.normal = Vec3::UnitY();
  const double band = 0.002;
  auto turned = [](double deg) {
    const double a = deg * M_PI / 180;
    return pack_side_normal(Vec3(std::sin(a), std::cos(a), 0));
  };
  const Vec3 on_plane = Vec3::Zero();
  EXPECT_EQ(side_near_plane(kSidePlus, turned(9.5), f, on_plane, band), kSidePlus);
  EXPECT_EQ(side_near_plane(kSideMinus, turned(-9.5), f, on_plane, band), kSideMinus);
  EXPECT_EQ(side_near_plane(kSidePlus, turned(10.5), f, on_plane, band), kSideNone);
  EXPECT_EQ(side_near_plane(kSideMinus, turned(90), f, Vec3(0, -0.001, 0), band), kSideNone);
  EXPECT_EQ(side_near_plane(kSidePlus, turned(180), f, on_plane, band), kSideNone);
  // A side that lapsed in a pass is not learned again in it (its normal is written only in a
  // pass that starts without a side, when no reader needs it).
  EXPECT_EQ(side_after_lapse(kSidePlus, kSideNone, kSideMinus), kSideNone);
  EXPECT_EQ(side_after_lapse(kSideNone, kSideNone, kSideMinus), kSideMinus);
  EXPECT_EQ(side_after_lapse(kSidePlus, kSidePlus, kSideMinus), kSidePlus);
}

}  // namespace
}  // namespace phyxel
