// GpuSolver::object_motion, the run loop's rest, sleep and runaway checks on the device: per
// object the kinetic energy and the largest speed, against the host's sums of the velocities
// it reads back, over objects of a few phyxels and of more than one reduction block.
#include <cmath>
#include <limits>
#include <random>

#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

// Three boxes far apart: 8, 12 and 7 x 7 x 7 = 343 phyxels (two levels of kScanBlock = 256).
PhyxelSet three_objects() {
  Scene scene = lattice_scene(2, 2, 2);
  const int sizes[2][3] = {{3, 2, 2}, {7, 7, 7}};
  for (int k = 0; k < 2; ++k) {
    const Vec3 lo(0.1 * (k + 1), 0, 0);
    const Vec3 hi = lo + kSpacing * Vec3(sizes[k][0] - 1, sizes[k][1] - 1, sizes[k][2] - 1);
    ObjectDesc o = box_scene(lo, hi, kSpacing, tissue(3e4 * (k + 1), 0.3, 1.0)).objects[0];
    o.name = "box" + std::to_string(k + 1);
    scene.objects.push_back(o);
  }
  return sample_scene(scene, SamplingOptions{false});
}

TEST_F(GpuSolverTest, ObjectMotionIsTheHostsSumOfTheVelocitiesPerObject) {
  const PhyxelSet set = three_objects();
  ASSERT_EQ(set.objects.size(), 3u);
  ASSERT_EQ(set.objects[2].count, 343u);
  GpuSolver gpu(ctx(), set, Vec3::Zero());
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> d(-1, 1);
  std::vector<Vec3> u(set.size(), Vec3::Zero()), v(set.size());
  for (Vec3& x : v) x = Vec3(d(rng), d(rng), d(rng));
  gpu.set_state(u, v);
  const std::vector<ObjectMotion> motion = gpu.object_motion(set);
  const std::vector<ObjectMotion> host = sum_object_motion(set, gpu.read_state(false).velocity);
  ASSERT_EQ(motion.size(), 3u);
  for (size_t o = 0; o < 3; ++o) {
    EXPECT_GT(host[o].kinetic, 0) << o;
    EXPECT_NEAR(motion[o].kinetic, host[o].kinetic, 1e-6 * host[o].kinetic) << o;
    EXPECT_NEAR(motion[o].max_speed, host[o].max_speed, 1e-6 * host[o].max_speed) << o;
  }
  // The same bits again: the sums are added in a fixed order.
  const std::vector<ObjectMotion> again = gpu.object_motion(set);
  for (size_t o = 0; o < 3; ++o) {
    EXPECT_EQ(again[o].kinetic, motion[o].kinetic);
    EXPECT_EQ(again[o].max_speed, motion[o].max_speed);
  }
  // A non-finite velocity shows in its object's largest speed, and only there.
  v[set.objects[2].first + 300] = Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0);
  gpu.set_state(u, v);
  const std::vector<ObjectMotion> bad = gpu.object_motion(set);
  EXPECT_TRUE(std::isnan(bad[2].max_speed));
  EXPECT_TRUE(std::isfinite(bad[0].max_speed) && std::isfinite(bad[1].max_speed));
  EXPECT_EQ(bad[1].kinetic, motion[1].kinetic);
}

TEST_F(GpuSolverTest, ObjectMotionRefusesAnotherSet) {
  const PhyxelSet set = three_objects();
  GpuSolver gpu(ctx(), set, Vec3::Zero());
  EXPECT_THROW(gpu.object_motion(lattice(2, 2, 2)), std::invalid_argument);
}

}  // namespace
}  // namespace phyxel::gpu::test
