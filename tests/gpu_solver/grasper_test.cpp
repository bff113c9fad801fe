// The grasper on the GPU against the CPU reference (engine/solver/grasper.h): the same phyxels
// taken when the jaws close, the same motion while they hold and pull (turning the tool's axis
// too), the same force on the tool, the same grip when held phyxels are removed, and the same
// letting go, with the motions given chunk by chunk as the run loop does; and the hold inside
// tool_contact's dispatch giving the bits of its own pass.
#include <gtest/gtest.h>

#include <cstdio>

#include "tests/gpu_solver/gpu_solver_fixture.h"
#include "tests/surgery/grasper_fixtures.h"

namespace phyxel::gpu::test {
namespace {

struct GripRun {
  std::vector<std::vector<Vec3>> u;         // after each chunk
  std::vector<std::vector<uint32_t>> held;  // after each chunk
  std::vector<ToolContactSample> samples;   // every substep
};

// With sleep_bar, object 0 (the bar) is put to sleep after chunk 5 (its held phyxels then in
// no candidate list) and woken after chunk 7.
GripRun grip(Solver& solver, const Scene& scene, const PhyxelSet& set, bool sleep_bar = false) {
  GripRun out;
  advance_tools_in_chunks(solver, scene, set, scene.simulation.steps, 8, [&](const auto& felt) {
    out.samples.insert(out.samples.end(), felt.begin(), felt.end());
    out.u.push_back(solver.read_state(false).displacement);
    out.held.push_back(solver.tools()->held_phyxels(0));
    // At 24 ms two held phyxels are aspirated: they leave the grip.
    if (out.held.size() == 3 && out.held.back().size() > 2)
      solver.removal()->remove_phyxels({out.held.back()[0], out.held.back()[1]});
    const size_t chunk = out.u.size();
    if (sleep_bar && (chunk == 5 || chunk == 7))
      solver.pass_selection()->set_object_awake(0, chunk == 7);
  });
  return out;
}

TEST_F(GpuSolverTest, GrasperCapturesHoldsAndReleasesAsTheCpu) {
  // The jaws close at 2 ms on the end of the bar, pull it 2 mm while the tool turns 17 degrees,
  // and open at 60 ms; 80 ms in all.
  const Scene scene = parse_scene(phyxel::test::bar_json(phyxel::test::kBarLength + 0.0006, 0.0027,
                                                         0.002, 0.06, 0.08, "[0.3, 0, 1]"),
                                  "bar.json");
  const PhyxelSet set = sample_scene(scene);
  auto cpu = make_cpu_solver(set, Vec3::Zero(), 1);
  GpuSolver gpu(ctx(), set, Vec3::Zero());
  const GripRun c = grip(*cpu, scene, set);
  const GripRun g = grip(gpu, scene, set);
  ASSERT_EQ(c.held.size(), g.held.size());
  size_t most = 0;
  double worst_u = 0, largest_u = 0;
  for (size_t k = 0; k < c.held.size(); ++k) {
    SCOPED_TRACE("chunk " + std::to_string(k));
    EXPECT_EQ(c.held[k], g.held[k]);
    most = std::max(most, c.held[k].size());
    worst_u = std::max(worst_u, max_difference(c.u[k], g.u[k]));
    largest_u = std::max(largest_u, max_norm(c.u[k]));
  }
  EXPECT_GT(most, 10u);
  ASSERT_GT(c.held.size(), 4u);
  EXPECT_EQ(c.held[3].size() + 2, c.held[2].size()) << "the removed phyxels are still held";
  EXPECT_TRUE(c.held.back().empty()) << "the jaws did not open";
  EXPECT_GT(largest_u, 0.0015);
  EXPECT_LT(worst_u, 1e-6);  // m
  ASSERT_EQ(c.samples.size(), g.samples.size());
  double worst_f = 0, largest_f = 0;
  for (size_t k = 0; k < c.samples.size(); ++k) {
    EXPECT_EQ(c.samples[k].held, g.samples[k].held) << k;
    largest_f = std::max(largest_f, c.samples[k].force.norm());
    worst_f = std::max(worst_f, (c.samples[k].force - g.samples[k].force).norm());
  }
  EXPECT_GT(largest_f, 1e-4);  // N
  EXPECT_LT(worst_f, 0.01 * largest_f);
  std::printf(
      "[ grasper  ] held up to %zu; |u| up to %.3g m, GPU within %.3g m; force up to %.3g N, "
      "within %.3g N\n",
      most, largest_u, worst_u, largest_f, worst_f);
}

// The bar, and a box far from the tool (index 1) that stays awake when the bar sleeps.
std::string bar_and_far_box_json() {
  std::string j = phyxel::test::bar_json(phyxel::test::kBarLength + 0.0006, 0.0027, 0.002, 0.06,
                                         0.08, "[0.3, 0, 1]");
  const std::string end_of_bar = "}]}],\n  \"tools\"";
  const size_t at = j.find(end_of_bar);
  if (at == std::string::npos) return j;
  j.insert(at + 3, R"(, {"name": "far", "shape": {"type": "box", "min": [0.1, -0.002, -0.002],
    "max": [0.106, 0.002, 0.002]}, "spacing": 0.001,
    "material": {"young": 1e4, "poisson": 0, "density": 1000, "damping": 100}})");
  return j;
}

// The hold inside tool_contact (grasp_in_contact) against its own pass after it: the same
// bits, while the held phyxels are candidates, removed, or asleep (no candidates).
TEST_F(GpuSolverTest, GrasperHoldInsideContactGivesTheBitsOfItsOwnPass) {
  const Scene scene = parse_scene(bar_and_far_box_json(), "bar.json");
  const PhyxelSet set = sample_scene(scene);
  ASSERT_EQ(set.objects.size(), 2u);
  GpuSolverOptions own;
  own.grasp_in_contact = false;
  GpuSolver fused(ctx(), set, Vec3::Zero());
  GpuSolver separate(ctx(), set, Vec3::Zero(), own);
  const GripRun f = grip(fused, scene, set, true);
  const GripRun s = grip(separate, scene, set, true);
  ASSERT_EQ(f.held.size(), s.held.size());
  ASSERT_GT(f.held.size(), 8u);
  size_t most = 0;
  for (size_t k = 0; k < f.held.size(); ++k) {
    SCOPED_TRACE("chunk " + std::to_string(k));
    EXPECT_EQ(f.held[k], s.held[k]);
    EXPECT_EQ(f.u[k], s.u[k]);
    most = std::max(most, f.held[k].size());
  }
  EXPECT_GT(most, 10u);
  EXPECT_FALSE(f.held[6].empty()) << "nothing held while the bar slept";
  EXPECT_NE(f.u[5], f.u[6]) << "the sleeping bar's held phyxels did not move";
  ASSERT_EQ(f.samples.size(), s.samples.size());
  for (size_t k = 0; k < f.samples.size(); ++k) {
    EXPECT_EQ(f.samples[k].force, s.samples[k].force) << k;
    EXPECT_EQ(f.samples[k].held, s.samples[k].held) << k;
  }
}

// The contact and hold inside the force pass (contact_in_force, solver_force_contact: each
// listed phyxel's hold after its drift, the sleeping bar's held phyxels outside the list, the
// grip's sums beside the next pass) against tool_contact's: the same bits, while the held
// phyxels are candidates, removed, or asleep.
TEST_F(GpuSolverTest, GrasperHoldInsideTheForcePassGivesTheBitsOfToolContact) {
  const Scene scene = parse_scene(bar_and_far_box_json(), "bar.json");
  const PhyxelSet set = sample_scene(scene);
  GpuSolverOptions after;
  after.contact_in_force = false;
  GpuSolver fused(ctx(), set, Vec3::Zero());
  GpuSolver contact(ctx(), set, Vec3::Zero(), after);
  const GripRun f = grip(fused, scene, set, true);
  const GripRun c = grip(contact, scene, set, true);
  ASSERT_EQ(f.held.size(), c.held.size());
  ASSERT_GT(f.held.size(), 8u);
  EXPECT_FALSE(f.held[6].empty()) << "nothing held while the bar slept";
  for (size_t k = 0; k < f.held.size(); ++k) {
    SCOPED_TRACE("chunk " + std::to_string(k));
    EXPECT_EQ(f.held[k], c.held[k]);
    EXPECT_EQ(f.u[k], c.u[k]);
  }
  ASSERT_EQ(f.samples.size(), c.samples.size());
  for (size_t k = 0; k < f.samples.size(); ++k) {
    EXPECT_EQ(f.samples[k].force, c.samples[k].force) << k;
    EXPECT_EQ(f.samples[k].contacts, c.samples[k].contacts) << k;
    EXPECT_EQ(f.samples[k].held, c.samples[k].held) << k;
  }
}

}  // namespace
}  // namespace phyxel::gpu::test
