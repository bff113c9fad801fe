// Aspiration's reads without the whole state (Solver::read_near, read_displacements): on the GPU
// (solver_near) exactly what the whole state read back and filtered gives, bit for bit, and
// the same phyxels with the same values (within float) as the CPU reference's.
#include <algorithm>
#include <memory>

#include "engine/solver/solver.h"
#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

// A box whose faces lie half a spacing from the lattice's planes: no phyxel near a face.
Bounds inner_box() {
  const Vec3 origin(0.01, -0.02, 0.003);
  return Bounds{origin + kSpacing * Vec3(2.5, 1.5, 1.5), origin + kSpacing * Vec3(6.5, 4.5, 3.5)};
}

TEST_F(GpuSolverTest, ReadNearGivesWhatTheWholeStateGivesAndTheCpusPhyxels) {
  const Scene scene = lattice_scene(9, 7, 6, tissue(2e5, 0.35, 5.0));
  const PhyxelSet set = sample_scene(scene);
  GpuSolver gpu(ctx(), set, Vec3(0, 0, -9.81));
  gpu.set_principal_stress(true);
  std::vector<Vec3> u, v;
  deformed_state(set, 5, 2e-5, u, v);
  gpu.set_state(u, v);
  gpu.advance(20, plan_time_step(scene, set).dt_stable);
  const uint32_t removed = 3 * 63 + 3 * 9 + 4;  // inside the box: still read (not a filter)
  gpu.remove_phyxels({removed});

  const NearState near = gpu.read_near(set, inner_box());
  const NearState whole = gpu.Solver::read_near(set, inner_box());  // the whole state, filtered
  ASSERT_EQ(near.ids.size(), 4u * 3u * 2u);
  EXPECT_EQ(near.ids, whole.ids);
  EXPECT_EQ(near.displacement, whole.displacement);
  EXPECT_EQ(near.principal, whole.principal);
  EXPECT_GT(*std::max_element(near.principal.begin(), near.principal.end()), 0.0);

  // A gather by id, in the order asked.
  std::vector<uint32_t> ids = {377, 0, 200, removed};
  const std::vector<Vec3> gathered = gpu.read_displacements(ids);
  const PointState state = gpu.read_state(false);
  ASSERT_EQ(gathered.size(), ids.size());
  for (size_t k = 0; k < ids.size(); ++k) EXPECT_EQ(gathered[k], state.displacement[ids[k]]);

  // The CPU twin on the same state.
  auto cpu = make_cpu_solver(set, Vec3(0, 0, -9.81), 1);
  cpu->principal_stress()->set_principal_stress(true);
  cpu->removal()->remove_phyxels({removed});
  cpu->set_state(state.displacement, state.velocity);
  const NearState twin = cpu->read_near(set, inner_box());
  EXPECT_EQ(twin.ids, near.ids);
  ASSERT_EQ(twin.principal.size(), near.principal.size());
  const double sigma = *std::max_element(twin.principal.begin(), twin.principal.end());
  for (size_t k = 0; k < twin.ids.size(); ++k) {
    EXPECT_LE((twin.displacement[k] - near.displacement[k]).norm(), 1e-12) << twin.ids[k];
    // A removed phyxel's stress is no solver's to say (the GPU keeps its last, the CPU 0).
    if (twin.ids[k] != removed) {
      EXPECT_NEAR(twin.principal[k], near.principal[k], 2e-3 * sigma) << twin.ids[k];
    }
  }
  EXPECT_EQ(cpu->read_displacements(ids), gathered);
}

// prefetch_near: the advance records read_near's passes at its end; the read after it gives
// the bits of a read in a submission of its own, and any call that touches the GPU in between
// (an edit, another advance) or another box reads afresh.
TEST_F(GpuSolverTest, PrefetchedReadNearGivesTheBitsOfItsOwnSubmission) {
  const Scene scene = lattice_scene(9, 7, 6, tissue(2e5, 0.35, 5.0));
  const PhyxelSet set = sample_scene(scene);
  const double dt = plan_time_step(scene, set).dt_stable;
  std::vector<Vec3> u, v;
  deformed_state(set, 5, 2e-5, u, v);
  auto make = [&] {
    auto s = std::make_unique<GpuSolver>(ctx(), set, Vec3(0, 0, -9.81));
    s->set_principal_stress(true);
    s->set_state(u, v);
    return s;
  };
  auto same = [](const NearState& a, const NearState& b) {
    EXPECT_EQ(a.ids, b.ids);
    EXPECT_EQ(a.displacement, b.displacement);
    EXPECT_EQ(a.principal, b.principal);
  };
  auto a = make(), b = make();
  Bounds other = inner_box();
  other.grow(kSpacing);

  a->prefetch_near(inner_box());
  a->advance(20, dt);
  b->advance(20, dt);
  EXPECT_TRUE(a->near_prefetched());
  EXPECT_FALSE(b->near_prefetched());
  (void)a->severed_since(0);  // the host's log: the prefetched read stays
  EXPECT_TRUE(a->near_prefetched());
  const NearState first = a->read_near(set, inner_box());
  EXPECT_FALSE(a->near_prefetched());  // once
  same(first, b->read_near(set, inner_box()));
  ASSERT_FALSE(first.ids.empty());

  // Another box than the prefetched one.
  a->prefetch_near(inner_box());
  a->advance(7, dt);
  b->advance(7, dt);
  same(a->read_near(set, other), b->read_near(set, other));

  // An edit after the advance: its forces change the principal stress near it.
  const uint32_t removed = 3 * 63 + 3 * 9 + 4;
  a->prefetch_near(inner_box());
  a->advance(5, dt);
  b->advance(5, dt);
  a->remove_phyxels({removed});
  b->remove_phyxels({removed});
  EXPECT_FALSE(a->near_prefetched());
  same(a->read_near(set, inner_box()), b->read_near(set, inner_box()));

  // Asked for one advance only.
  a->prefetch_near(inner_box());
  a->advance(3, dt);
  a->advance(3, dt);
  b->advance(6, dt);
  EXPECT_FALSE(a->near_prefetched());
  same(a->read_near(set, inner_box()), b->read_near(set, inner_box()));
}

}  // namespace
}  // namespace phyxel::gpu::test
