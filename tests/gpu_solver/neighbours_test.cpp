// The GPU neighbour search against the CPU's (engine/solver/neighbours.cpp): the same rows, sorted,
// on awkward sizes (not multiples of the workgroup size), two objects, removed phyxels and
// wider supports; the stored pair weights are the poly6 weights.
#include "engine/solver/neighbours.h"
#include "engine/solver/kernel.h"
#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

void expect_same_lists(const NeighbourLists& gpu, const NeighbourLists& cpu, const char* what) {
  ASSERT_EQ(gpu.offset.size(), cpu.offset.size()) << what;
  for (size_t i = 0; i + 1 < cpu.offset.size(); ++i) {
    const std::vector<uint32_t> g(gpu.index.begin() + gpu.offset[i],
                                  gpu.index.begin() + gpu.offset[i + 1]);
    const std::vector<uint32_t> c(cpu.index.begin() + cpu.offset[i],
                                  cpu.index.begin() + cpu.offset[i + 1]);
    ASSERT_EQ(g, c) << what << ": phyxel " << i;  // equal as sequences: same set, both sorted
    EXPECT_TRUE(std::is_sorted(g.begin(), g.end()));
  }
  EXPECT_EQ(gpu.index, cpu.index) << what;
}

// Both support tests: double (where the device has it; lavapipe has) and float.
void check_set(Context& ctx, const PhyxelSet& set, const char* what) {
  const NeighbourLists cpu = find_rest_neighbours(set);
  for (const auto test :
       {GpuSolverOptions::SupportTest::Auto, GpuSolverOptions::SupportTest::Float32}) {
    GpuSolverOptions options;
    options.support_test = test;
    const GpuSolver solver(ctx, set, Vec3::Zero(), options);
    SCOPED_TRACE(test == GpuSolverOptions::SupportTest::Auto ? "auto" : "float");
    expect_same_lists(solver.neighbours(), cpu, what);
    EXPECT_EQ(solver.pair_count(), solver.neighbours().index.size());
  }
}

TEST_F(GpuSolverTest, NeighboursMatchTheCpuOnAwkwardSizes) {
  check_set(ctx(), lattice(1, 1, 1), "1 phyxel");
  check_set(ctx(), lattice(13, 1, 1), "13 x 1 x 1");
  check_set(ctx(), lattice(127, 1, 1), "127 x 1 x 1");
  check_set(ctx(), lattice(7, 5, 3), "7 x 5 x 3");
  check_set(ctx(), lattice(10, 10, 10), "10 x 10 x 10");
}

TEST_F(GpuSolverTest, NeighboursMatchTheCpuForWiderSupports) {
  check_set(ctx(), lattice(9, 7, 6, tissue(), 2.3), "h = 2.3 s");
  check_set(ctx(), lattice(7, 6, 5, tissue(), 3.0), "h = 3 s");
  check_set(ctx(), lattice(8, 5, 4, tissue(), 1.45), "h = 1.45 s");
}

TEST_F(GpuSolverTest, NeighboursStayWithinTheirObjectAndSkipRemovedPhyxels) {
  Scene scene = lattice_scene(6, 5, 4);
  ObjectDesc second = scene.objects[0];
  second.name = "touching";
  // Shifted by exactly one spacing beyond the first box: lattice points of the two objects
  // are closer than h, but never neighbours.
  second.shape = box_shape(scene.objects[0].shape.max + Vec3(kSpacing, -0.004, -0.002),
                           scene.objects[0].shape.max + Vec3(6 * kSpacing, 0.003, 0.004));
  second.spacing = 0.002;
  second.support_radius = 0.0045;
  scene.objects.push_back(second);
  PhyxelSet set = sample_scene(scene);
  ASSERT_EQ(set.objects.size(), 2u);
  check_set(ctx(), set, "two objects");
  for (size_t i = 0; i < set.size(); i += 7) set.flags[i] |= kRemoved;
  check_set(ctx(), set, "two objects, every 7th phyxel removed");
}

TEST_F(GpuSolverTest, PairWeightsArePoly6OfTheRestDistance) {
  const PhyxelSet set = lattice(7, 6, 5, tissue(), 2.5);
  GpuSolver solver(ctx(), set, Vec3::Zero());
  const NeighbourLists& nbr = solver.neighbours();
  const std::vector<float> w = solver.pair_weights();
  ASSERT_EQ(w.size(), nbr.index.size());
  const double h = set.objects[0].support_radius;
  double largest = 0;
  for (size_t k = 0; k < w.size(); ++k) largest = std::max(largest, double(w[k]));
  ASSERT_GT(largest, 0);
  for (size_t i = 0; i < set.size(); ++i) {
    for (uint32_t k = nbr.offset[i]; k < nbr.offset[i + 1]; ++k) {
      const double expected = poly6((set.rest[nbr.index[k]] - set.rest[i]).squaredNorm(), h);
      EXPECT_NEAR(w[k], expected, 1e-5 * largest) << "pair " << i << " " << nbr.index[k];
    }
  }
}

}  // namespace
}  // namespace phyxel::gpu::test
