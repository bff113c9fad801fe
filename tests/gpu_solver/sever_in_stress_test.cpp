// The cut pass inside the stress pass (GpuSolverOptions::sever_in_stress_max, solver_stress_sever)
// against tool_sever and solver_stress as two dispatches: the same severed pairs and the same
// bits of u and of every sample, for a scalpel crossing the beam a few pairs a substep, with
// four lanes per phyxel (the last workgroup's stress in rounds of 16), the principal stress on
// and, in the first advance (no candidate count yet), one workgroup looping over the candidates;
// and for a blade through the whole beam in one substep (hundreds of dirty phyxels).
#include <cstdio>
#include <set>
#include <utility>

#include "engine/surgery/tool_track.h"
#include "tests/cutting/cutting_fixtures.h"
#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

using phyxel::test::clamped_beam;
using phyxel::test::crossing_scalpel;

struct BeamRun {
  std::set<std::pair<uint32_t, uint32_t>> severed;
  std::vector<Vec3> u;
  std::vector<uint8_t> alive;
  std::vector<ToolContactSample> samples;
};

BeamRun run_beam(const Scene& scene, Context& ctx, bool fused, int64_t steps, int64_t chunk) {
  const PhyxelSet set = sample_scene(scene);
  GpuSolverOptions options;
  options.lanes = 4;
  if (!fused) options.sever_in_stress_max = 0;
  GpuSolver gpu(ctx, set, scene.simulation.gravity, options);
  gpu.set_principal_stress(true);
  ToolTrack track(scene.tools, {});
  gpu.set_tools(contact_tools(scene.tools));
  BeamRun out;
  for (int64_t s = 0; s < steps; s += chunk) {
    const int64_t n = std::min(chunk, steps - s);
    gpu.set_tool_motion(track.motions(s, n, scene.simulation.dt));
    gpu.advance(n, scene.simulation.dt);
    const std::vector<ToolContactSample> felt = gpu.tool_samples();
    out.samples.insert(out.samples.end(), felt.begin(), felt.end());
  }
  for (const SeveredPair& p : gpu.severed_since(0)) out.severed.insert({p.i, p.j});
  out.u = gpu.read_state(false).displacement;
  out.alive = gpu.pair_alive();
  return out;
}

void expect_same_bits(const BeamRun& f, const BeamRun& s) {
  EXPECT_EQ(f.severed, s.severed);
  EXPECT_EQ(f.alive, s.alive);
  ASSERT_EQ(f.u.size(), s.u.size());
  for (size_t i = 0; i < f.u.size(); ++i) ASSERT_EQ(f.u[i], s.u[i]) << i;
  ASSERT_EQ(f.samples.size(), s.samples.size());
  for (size_t k = 0; k < f.samples.size(); ++k) {
    EXPECT_EQ(f.samples[k].force, s.samples[k].force) << k;
    EXPECT_EQ(f.samples[k].contacts, s.samples[k].contacts) << k;
  }
}

TEST_F(GpuSolverTest, SeverInsideTheStressPassGivesTheBitsOfTwoPasses) {
  Scene scene = clamped_beam();
  scene.tools.push_back(crossing_scalpel(0.009, -0.003, 0.016, 0.002, 0.016));
  const BeamRun f = run_beam(scene, ctx(), true, 400, 16);
  const BeamRun s = run_beam(scene, ctx(), false, 400, 16);
  EXPECT_GT(f.severed.size(), 100u);
  expect_same_bits(f, s);
  std::printf("[ fused    ] %zu pairs severed: the same bits\n", f.severed.size());
}

TEST_F(GpuSolverTest, SeverInsideTheStressPassThroughTheBeamInOneSubstep) {
  Scene scene = clamped_beam();
  scene.objects[0].spacing = 0.001;
  scene.objects[0].support_radius = 0.0025;
  scene.simulation.dt = 5e-5;
  scene.tools.push_back(crossing_scalpel(0.0093, -0.003, 0.016, 0.0005, 5e-5));
  const BeamRun f = run_beam(scene, ctx(), true, 40, 16);
  const BeamRun s = run_beam(scene, ctx(), false, 40, 16);
  EXPECT_GT(f.severed.size(), 300u);
  expect_same_bits(f, s);
}

}  // namespace
}  // namespace phyxel::gpu::test
