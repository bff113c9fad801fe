// The neighbour index and the pair weights in two parts (PairBuffer, pair_buffers.glsl), as a
// scene past one binding's maxStorageBufferRange (about 41M phyxels of a lattice) has them:
// GpuSolverOptions::pair_part_bytes splits a small scene's pairs mid-row, and every pass that
// reads or writes pairs (the neighbour search, precompute, stress, force, energy, von Mises,
// principal stress, tearing, a scalpel's sever pass, removal) gives the bits of the solver
// that binds them whole. More pairs than two parts hold are refused with the sizes.
#include "engine/surgery/tool_track.h"
#include "tests/cutting/cutting_fixtures.h"
#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

using phyxel::test::clamped_beam;
using phyxel::test::crossing_scalpel;
using phyxel::test::PulledBar;

// Options that put a little less than half of `pairs` in the lo part: 7 pairs past the
// middle is not a row boundary of a lattice, so a row straddles the parts.
GpuSolverOptions split_near_half(uint64_t pairs, GpuSolverOptions options = {}) {
  options.pair_part_bytes = (pairs / 2 + 7) * 4;
  return options;
}

struct Outcome {
  NeighbourLists neighbours;
  std::vector<SeveredPair> severed;
  std::vector<float> weights;
  PointState state;
  Energies energies;
};

// A scalpel across the clamped beam, with principal stress on, then two phyxels removed.
Outcome cut_and_remove(Context& ctx, const Scene& scene, const PhyxelSet& set,
                       const GpuSolverOptions& options) {
  GpuSolver gpu(ctx, set, scene.simulation.gravity, options);
  gpu.set_principal_stress(true);
  ToolTrack track(scene.tools, {});
  gpu.set_tools(contact_tools(scene.tools));
  const double dt = scene.simulation.dt;
  for (int64_t s = 0; s < 240; s += 48) {
    gpu.set_tool_motion(track.motions(s, 48, dt));
    gpu.advance(48, dt);
  }
  gpu.remove_phyxels({3, 40});
  gpu.advance(16, dt);
  return {gpu.neighbours(), gpu.severed_since(0), gpu.pair_weights(), gpu.read_state(true),
          gpu.energies()};
}

void expect_same(const Outcome& whole, const Outcome& split) {
  EXPECT_EQ(whole.neighbours.offset, split.neighbours.offset);
  EXPECT_EQ(whole.neighbours.index, split.neighbours.index);
  ASSERT_EQ(whole.severed.size(), split.severed.size());
  for (size_t k = 0; k < whole.severed.size(); ++k) {
    EXPECT_EQ(whole.severed[k].i, split.severed[k].i) << k;
    EXPECT_EQ(whole.severed[k].j, split.severed[k].j) << k;
    EXPECT_EQ(whole.severed[k].torn, split.severed[k].torn) << k;
  }
  EXPECT_EQ(whole.weights, split.weights);
  EXPECT_EQ(whole.state.displacement, split.state.displacement);
  EXPECT_EQ(whole.state.velocity, split.state.velocity);
  EXPECT_EQ(whole.state.von_mises, split.state.von_mises);
  EXPECT_EQ(whole.state.max_principal_stress, split.state.max_principal_stress);
  EXPECT_EQ(whole.energies.strain, split.energies.strain);
  EXPECT_EQ(whole.energies.kinetic, split.energies.kinetic);
}

TEST_F(GpuSolverTest, PairsInTwoPartsGiveTheBitsOfOneBindingThroughACutAndARemoval) {
  Scene scene = clamped_beam();
  scene.tools.push_back(crossing_scalpel(0.013, -0.003, 0.016, 0.0, 0.02));
  const PhyxelSet set = sample_scene(scene);
  const uint64_t pairs = GpuSolver(ctx(), set, scene.simulation.gravity).pair_count();
  for (const auto weights :
       {GpuSolverOptions::PairWeights::Auto, GpuSolverOptions::PairWeights::Stored}) {
    GpuSolverOptions options;
    options.pair_weights = weights;
    const Outcome whole = cut_and_remove(ctx(), scene, set, options);
    const Outcome split = cut_and_remove(ctx(), scene, set, split_near_half(pairs, options));
    ASSERT_GT(whole.severed.size(), 20u) << "the scalpel cut nothing";
    // The cut severed pairs on both sides of the split.
    size_t lo = 0, hi = 0;
    for (uint32_t i = 0; i < set.size(); ++i) {
      for (uint32_t k = whole.neighbours.offset[i]; k < whole.neighbours.offset[i + 1]; ++k) {
        if (whole.weights[k] != 0.0f) continue;
        (k < pairs / 2 + 7 ? lo : hi) += 1;
      }
    }
    EXPECT_GT(lo, 0u);
    EXPECT_GT(hi, 0u);
    expect_same(whole, split);
  }
}

TEST_F(GpuSolverTest, ABarTornApartWithPairsInTwoPartsIsTheOneBindingBar) {
  const PulledBar bar;
  const uint64_t pairs = GpuSolver(ctx(), bar.set, Vec3::Zero()).pair_count();
  auto pulled = [&](const GpuSolverOptions& options) {
    GpuSolver gpu(ctx(), bar.set, Vec3::Zero(), options);
    gpu.set_tearing(true);
    gpu.set_external_forces(bar.load(0.3));
    for (int k = 0; k < 6; ++k) gpu.advance(40, bar.dt);
    return std::make_pair(gpu.severed_since(0), gpu.read_state(false).displacement);
  };
  const auto [log_whole, u_whole] = pulled({});
  const auto [log_split, u_split] = pulled(split_near_half(pairs));
  ASSERT_GT(log_whole.size(), 10u);
  ASSERT_EQ(log_whole.size(), log_split.size());
  for (size_t k = 0; k < log_whole.size(); ++k) {
    EXPECT_EQ(log_whole[k].i, log_split[k].i) << k;
    EXPECT_EQ(log_whole[k].j, log_split[k].j) << k;
  }
  EXPECT_EQ(u_whole, u_split);
}

TEST_F(GpuSolverTest, MorePairsThanTwoPartsHoldAreRefusedWithTheSizes) {
  const PhyxelSet set = lattice(6, 5, 4);
  const uint64_t pairs = GpuSolver(ctx(), set, Vec3::Zero()).pair_count();
  GpuSolverOptions options;
  options.pair_part_bytes = (pairs / 3) * 4;  // three parts' worth
  try {
    GpuSolver gpu(ctx(), set, Vec3::Zero(), options);
    FAIL() << "a scene needing three parts was built";
  } catch (const VulkanError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(std::to_string(pairs) + " neighbour pairs"), std::string::npos) << what;
    EXPECT_NE(what.find("two parts of the neighbour index"), std::string::npos) << what;
    EXPECT_NE(what.find(ctx().info().name), std::string::npos) << what;
  }
  options.pair_part_bytes = (pairs / 2 + 64) * 4;  // two parts hold it
  EXPECT_NO_THROW(GpuSolver(ctx(), set, Vec3::Zero(), options));
}

}  // namespace
}  // namespace phyxel::gpu::test
