// Phyxel numbering (engine/sampling/phyxel_order.h): the Morton order is a permutation within
// each object that visits the lattice in Z-order; renumbering moves every per-phyxel array and
// the loads' phyxels with it; and the physics does not depend on the numbering.
#include <gtest/gtest.h>

#include <numeric>

#include "engine/sampling/phyxel_order.h"
#include "engine/solver/solver.h"
#include "sampling_helpers.h"

namespace phyxel::test {
namespace {

constexpr double kOrderSpacing = 0.0025;

// A box with a fixed face and a load on the other, and a sphere: two objects, two materials.
Scene two_objects() {
  ObjectDesc block = object("block", box(Vec3::Zero(), Vec3(0.02, 0.0125, 0.01)), kOrderSpacing);
  block.fixed.push_back(box(Vec3(-1, -1, -1), Vec3(0.0001, 1, 1)));
  Load pull;
  pull.region = box(Vec3(0.0199, -1, -1), Vec3(1, 1, 1));
  pull.force = Vec3(0.01, 0, -0.02);
  block.loads.push_back(pull);
  ObjectDesc ball = object("ball", sphere(Vec3(0.05, 0, 0), 0.008), kOrderSpacing);
  ball.material.young = 3e4;
  Scene scene = scene_of({block, ball});
  scene.simulation.gravity = Vec3(0, 0, -9.81);
  return scene;
}

TEST(PhyxelOrder, MortonIsAPermutationWithinEachObjectInZOrder) {
  const PhyxelSet set = sample_scene(two_objects());
  const std::vector<uint32_t> order = morton_order(set);
  ASSERT_EQ(order.size(), set.size());
  std::vector<uint32_t> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  std::vector<uint32_t> identity(set.size());
  std::iota(identity.begin(), identity.end(), 0u);
  EXPECT_EQ(sorted, identity);
  for (uint32_t k = 0; k < order.size(); ++k) EXPECT_EQ(set.object[order[k]], set.object[k]) << k;
  // The block's first eight phyxels are the 2 x 2 x 2 cube at its lowest corner, in the order
  // (x, y, z) bits 000, 100, 010, 110, 001, ...
  for (uint32_t k = 0; k < 8; ++k) {
    const Vec3 want = kOrderSpacing * Vec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
    EXPECT_LT((set.rest[order[k]] - want).norm(), 1e-12) << k;
  }
  // Then the next 2 x 2 x 2 cube along x.
  EXPECT_LT((set.rest[order[8]] - Vec3(2 * kOrderSpacing, 0, 0)).norm(), 1e-12);
}

TEST(PhyxelOrder, PermutingMovesEveryArrayAndTheLoads) {
  const PhyxelSet set = sample_scene(two_objects());
  PhyxelSet moved = set;
  const std::vector<uint32_t> order = morton_order(set);
  permute_phyxels(moved, order);
  ASSERT_EQ(moved.size(), set.size());
  for (uint32_t k = 0; k < set.size(); ++k) {
    const uint32_t i = order[k];
    EXPECT_EQ(moved.rest[k], set.rest[i]);
    EXPECT_EQ(moved.volume[k], set.volume[i]);
    EXPECT_EQ(moved.mass[k], set.mass[i]);
    EXPECT_EQ(moved.material[k], set.material[i]);
    EXPECT_EQ(moved.object[k], set.object[i]);
    EXPECT_EQ(moved.flags[k], set.flags[i]);
    EXPECT_EQ(moved.normal[k], set.normal[i]);
    EXPECT_EQ(moved.splat_radius[k], set.splat_radius[i]);
    EXPECT_EQ(moved.external_force[k], set.external_force[i]);
  }
  ASSERT_EQ(moved.loads.size(), 1u);
  ASSERT_FALSE(set.loads[0].phyxels.empty());
  for (size_t n = 0; n < set.loads[0].phyxels.size(); ++n)
    EXPECT_EQ(moved.rest[moved.loads[0].phyxels[n]], set.rest[set.loads[0].phyxels[n]]) << n;
  EXPECT_EQ(external_forces_at(moved, 0.0), moved.external_force);
}

TEST(PhyxelOrder, PermutationsThatAreNotOrLeaveAnObjectAreRefused) {
  const PhyxelSet set = sample_scene(two_objects());
  std::vector<uint32_t> order(set.size());
  std::iota(order.begin(), order.end(), 0u);
  PhyxelSet copy = set;
  std::vector<uint32_t> twice = order;
  twice[1] = 0;
  EXPECT_THROW(permute_phyxels(copy, twice), std::invalid_argument);
  EXPECT_THROW(permute_phyxels(copy, std::vector<uint32_t>(3, 0)), std::invalid_argument);
  std::vector<uint32_t> across = order;
  std::swap(across.front(), across.back());  // the block's first and the ball's last
  EXPECT_THROW(permute_phyxels(copy, across), std::invalid_argument);
  EXPECT_EQ(copy.rest, set.rest);  // a refused order changes nothing
}

TEST(PhyxelOrder, TheMotionDoesNotDependOnTheNumbering) {
  const Scene scene = two_objects();
  const PhyxelSet set = sample_scene(scene);
  PhyxelSet moved = set;
  const std::vector<uint32_t> order = morton_order(set);
  permute_phyxels(moved, order);
  auto a = make_cpu_solver(set, scene.simulation.gravity, 1);
  auto b = make_cpu_solver(moved, scene.simulation.gravity, 1);
  for (Solver* s : {a.get(), b.get()}) s->advance(200, 2e-5);
  const std::vector<Vec3> ua = a->read_state(false).displacement;
  const std::vector<Vec3> ub = b->read_state(false).displacement;
  double largest = 0, worst = 0;
  for (uint32_t k = 0; k < set.size(); ++k) {
    largest = std::max(largest, ua[order[k]].norm());
    worst = std::max(worst, (ub[k] - ua[order[k]]).norm());
  }
  ASSERT_GT(largest, 1e-7);
  // The neighbour sums are added in another order: equal to rounding.
  EXPECT_LT(worst, 1e-9 * largest);
}

}  // namespace
}  // namespace phyxel::test
