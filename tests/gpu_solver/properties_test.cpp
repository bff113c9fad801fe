// Property tests of the GPU path (DESIGN.md section 6), with float32 tolerances: the patch
// test, rigid motions, the balance of internal forces, the non-finite check, and the memory
// the solver takes.
#include <Eigen/Geometry>
#include <limits>

#include "compute/gpu_solver_setup.h"
#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

std::vector<Vec3> linear_field(const PhyxelSet& set, const Eigen::Matrix3d& g, const Vec3& t) {
  std::vector<Vec3> u(set.size());
  for (size_t i = 0; i < set.size(); ++i) u[i] = g * (set.rest[i] - set.rest[0]) + t;
  return u;
}

TEST_F(GpuSolverTest, UniformStrainGivesNoInternalForceInside) {
  const PhyxelSet set = lattice(9, 8, 7);
  GpuSolver solver(ctx(), set, Vec3::Zero());
  ASSERT_EQ(solver.regularised_count(), 0u);
  Eigen::Matrix3d g;
  g << 0.05, 0.01, 0, 0.01, -0.02, 0.003, 0, 0.003, 0.01;
  solver.set_state(linear_field(set, g, Vec3(1e-3, 0, 0)),
                   std::vector<Vec3>(set.size(), Vec3::Zero()));
  const std::vector<Vec3> f = solver.forces();
  const double scale = max_norm(f);
  ASSERT_GT(scale, 0);
  const NeighbourLists& nbr = solver.neighbours();
  size_t deep_count = 0;
  for (size_t i = 0; i < set.size(); ++i) {
    bool deep = nbr.count(i) == 26;
    for (uint32_t k = nbr.offset[i]; deep && k < nbr.offset[i + 1]; ++k)
      deep = nbr.count(nbr.index[k]) == 26;
    if (!deep) continue;
    ++deep_count;
    EXPECT_LT(f[i].norm(), 1e-4 * scale) << "phyxel " << i;
  }
  EXPECT_EQ(deep_count, size_t{5 * 4 * 3});
}

TEST_F(GpuSolverTest, RigidMotionsGiveNoForceAndNoEnergy) {
  const PhyxelSet set = lattice(8, 6, 5);
  GpuSolver solver(ctx(), set, Vec3::Zero());
  const std::vector<Vec3> rest_v(set.size(), Vec3::Zero());
  solver.set_state(linear_field(set, Eigen::Vector3d(0.01, 0, 0).asDiagonal(), Vec3::Zero()),
                   rest_v);
  const double stretch_force = max_norm(solver.forces());
  const double stretch_energy = solver.energies().strain;
  ASSERT_GT(stretch_force, 0);
  for (double angle : {0.3, 1.5707963, 3.1}) {
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(angle, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    solver.set_state(linear_field(set, r - Eigen::Matrix3d::Identity(), Vec3(1e-3, -2e-3, 3e-3)),
                     rest_v);
    // float32 u: the differences u_j - u_i carry relative errors of about 1e-6.
    EXPECT_LT(max_norm(solver.forces()), 2e-3 * stretch_force) << "angle " << angle;
    EXPECT_LT(solver.energies().strain, 1e-6 * stretch_energy) << "angle " << angle;
  }
}

TEST_F(GpuSolverTest, InternalForcesSumToZero) {
  const PhyxelSet set = lattice(7, 6, 5, tissue(), 2.5);
  GpuSolver solver(ctx(), set, Vec3::Zero());
  std::vector<Vec3> u, v;
  deformed_state(set, 17, 5e-5, u, v);
  solver.set_state(u, v);
  const std::vector<Vec3> f = solver.forces();
  Vec3 sum = Vec3::Zero();
  double magnitude = 0;
  for (const Vec3& x : f) {
    sum += x;
    magnitude += x.norm();
  }
  ASSERT_GT(magnitude, 0);
  EXPECT_LT(sum.norm(), 1e-5 * magnitude);
}

TEST_F(GpuSolverTest, FirstNonFiniteFindsTheLowestBadPhyxel) {
  const PhyxelSet set = lattice(7, 5, 3);
  GpuSolver solver(ctx(), set, Vec3(0, 0, -9.81));
  solver.advance(3, 1e-5);
  EXPECT_EQ(solver.first_non_finite(), -1);
  PointState s = solver.read_state(false);
  s.velocity[77].y() = std::numeric_limits<double>::infinity();
  s.displacement[93].x() = std::numeric_limits<double>::quiet_NaN();
  s.displacement[31].z() = std::numeric_limits<double>::quiet_NaN();
  solver.set_state(s.displacement, s.velocity);
  EXPECT_EQ(solver.first_non_finite(), 31);
}

TEST_F(GpuSolverTest, MemoryStaysWithinTheBoundAndUnderAKibibytePerPhyxel) {
  const PhyxelSet set = lattice(12, 12, 12);
  const uint64_t before = ctx().allocated_bytes();
  GpuSolver solver(ctx(), set, Vec3::Zero());
  const uint64_t used = ctx().allocated_bytes() - before;
  EXPECT_LE(used, GpuSolver::required_device_bytes(set));
  EXPECT_LE(double(used) / double(set.size()), 1024.0);
  EXPECT_LE(solver.pair_count(), lattice_pair_bound(set));
  const SolverBuffers b = solver.buffers();
  EXPECT_EQ(b.count, set.size());
  EXPECT_EQ(b.rest->size(), set.size() * 16);
  EXPECT_EQ(b.displacement->size(), set.size() * 16);
  EXPECT_EQ(b.nbr_offset->size(), (set.size() + 1) * 4);
  EXPECT_EQ(b.nbr_index->size(), solver.pair_count() * 4);
}

}  // namespace
}  // namespace phyxel::gpu::test
