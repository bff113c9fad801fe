// The precompute pass against the CPU reference's moment matrices: A_i^-1 (regularised where
// the condition number exceeds 100) and which phyxels were regularised, on a full box, a
// one-layer plate, a line and a lone phyxel.
#include "engine/solver/kernel.h"
#include "engine/solver/mls_model.h"
#include "engine/solver/neighbours.h"
#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

// The CPU's A_i^-1 (engine/solver/cpu_solver.cpp, constructor) for every phyxel.
std::vector<MomentInverse> cpu_inverses(const PhyxelSet& set) {
  const NeighbourLists nbr = find_rest_neighbours(set);
  std::vector<MomentInverse> out(set.size());
  for (size_t i = 0; i < set.size(); ++i) {
    const double h = set.objects[set.object[i]].support_radius;
    Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
    for (uint32_t k = nbr.offset[i]; k < nbr.offset[i + 1]; ++k) {
      const Vec3 x = set.rest[nbr.index[k]] - set.rest[i];
      a += poly6(x.squaredNorm(), h) * x * x.transpose();
    }
    out[i] = regularised_inverse(a);
  }
  return out;
}

// regularised < 0: as many as the CPU regularises.
void check_inverses(Context& ctx, const PhyxelSet& set, const char* what, long regularised) {
  GpuSolver solver(ctx, set, Vec3::Zero());
  const std::vector<MomentInverseRow> gpu = solver.moment_inverses();
  const std::vector<MomentInverse> cpu = cpu_inverses(set);
  size_t count = 0, cpu_count = 0;
  for (size_t i = 0; i < set.size(); ++i) {
    const float* g = gpu[i].inverse;
    Eigen::Matrix3d a;
    a << g[0], g[1], g[2], g[1], g[3], g[4], g[2], g[4], g[5];
    const double scale = cpu[i].inverse.cwiseAbs().maxCoeff();
    EXPECT_LE((a - cpu[i].inverse).cwiseAbs().maxCoeff(), 1e-4 * scale)
        << what << ": phyxel " << i << "\ngpu\n"
        << a << "\ncpu\n"
        << cpu[i].inverse;
    EXPECT_EQ(gpu[i].regularised, cpu[i].regularised) << what << ": phyxel " << i;
    if (gpu[i].regularised) ++count;
    if (cpu[i].regularised) ++cpu_count;
  }
  EXPECT_EQ(count, regularised < 0 ? cpu_count : size_t(regularised)) << what;
  EXPECT_EQ(solver.regularised_count(), count) << what;
}

TEST_F(GpuSolverTest, MomentInversesAndRegularisationMatchTheCpu) {
  check_inverses(ctx(), lattice(6, 5, 4), "6 x 5 x 4 box", 0);
  check_inverses(ctx(), lattice(7, 6, 1), "one-layer plate", 42);
  check_inverses(ctx(), lattice(13, 1, 1), "13 x 1 x 1 line", 13);
  check_inverses(ctx(), lattice(1, 1, 1), "a lone phyxel", 1);
  check_inverses(ctx(), lattice(5, 4, 4, tissue(), 1.45), "h = 1.45 s", -1);
}

}  // namespace
}  // namespace phyxel::gpu::test
