// The tool contact inside the force pass (GpuSolverOptions::contact_in_force: while tearing,
// solver_force_tear does tool_contact's work after the drift and tool_contact_reduce sums the
// samples after the advance) against tool_contact after it: the same bits in every state, tool
// force and aspirated amount, over a run that tears and aspirates (removed candidates); and the
// rows' per-substep samples against tool_contact's where each row has many partials and tools.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "engine/geometry/tool.h"
#include "engine/run/simulation.h"
#include "tests/cutting/cutting_fixtures.h"
#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

struct FusedRun : AspirationRun {
  bool rows_timed = false;  // a profile of the solver after the run has the rows' reduction
};

FusedRun aspirate(Context& ctx, const Scene& scene, const PhyxelSet& set, bool in_force,
                  uint32_t lanes) {
  GpuSolverOptions options;
  options.contact_in_force = in_force;
  options.lanes = lanes;  // the contact follows the lanes' sum in lane 0
  GpuSolver gpu(ctx, set, Vec3::Zero(), options);
  FusedRun out;
  static_cast<AspirationRun&>(out) = run_aspirating(scene, set, gpu, 200);
  for (const PassTime& t : gpu.profile(2, out.result.plan.dt_used))
    out.rows_timed = out.rows_timed || t.name == "contact: rows";
  return out;
}

void expect_same_bits(Context& ctx, uint32_t lanes) {
  const Scene scene =
      parse_scene(phyxel::test::suction_block_json(1000, true, 10000), "block.json");
  const PhyxelSet set = sample_scene(scene);
  const FusedRun fused = aspirate(ctx, scene, set, true, lanes);
  const FusedRun apart = aspirate(ctx, scene, set, false, lanes);
  EXPECT_TRUE(fused.rows_timed);
  EXPECT_FALSE(apart.rows_timed);
  ASSERT_TRUE(fused.result.aspirating);
  EXPECT_GE(fused.result.aspiration.events, 1);
  EXPECT_GT(fused.result.aspiration.removed_mass[0], 0);
  EXPECT_EQ(fused.result.aspiration.events, apart.result.aspiration.events);
  EXPECT_EQ(fused.result.aspiration.removed_mass, apart.result.aspiration.removed_mass);
  EXPECT_EQ(fused.state.displacement, apart.state.displacement);
  EXPECT_EQ(fused.state.velocity, apart.state.velocity);
  EXPECT_EQ(fused.state.contact, apart.state.contact);
  ASSERT_EQ(fused.forces.size(), apart.forces.size());
  double largest = 0;
  for (size_t k = 0; k < fused.forces.size(); ++k) {
    EXPECT_EQ(fused.forces[k], apart.forces[k]) << "step " << k;
    largest = std::max(largest, fused.forces[k].norm());
  }
  EXPECT_GT(largest, 0) << "the aspirator felt nothing";
}

TEST_F(GpuSolverTest, ContactInTheForcePassGivesToolContactsBits) {
  expect_same_bits(ctx(), 1);
}

TEST_F(GpuSolverTest, ContactInTheForcePassWithFourLanesGivesToolContactsBits) {
  expect_same_bits(ctx(), 4);
}

// Two tools pressing into a plate of 70 x 70 x 3 phyxels, bottom fixed, while tearing: a sphere
// of 10 cm whose bounds take both free layers (9 800 candidates, 154 partials of 64: threads of
// the sum add two or three) and a capsule across it, 5 advances of 8 substeps (rows 1 to 7
// each). Measured: up to 106 and 24 contacts; swapping two lanes of the rows' partial tree
// fails it (rotations and reflections of the lanes are the tree's symmetries, the same bits).
struct PlateRun {
  std::vector<ToolContactSample> samples;  // per advance, substep x tool
  PointState state;
  size_t candidates = 0;
  bool rows_timed = false;
};

PlateRun press_plate(Context& ctx, const Scene& scene, const PhyxelSet& set, bool in_force) {
  const double dt = plan_time_step(scene, set).dt_stable;
  const Vec3 lo = scene.objects[0].shape.min, hi = scene.objects[0].shape.max;
  const Vec3 mid(0.5 * (lo.x() + hi.x()), 0.5 * (lo.y() + hi.y()), hi.z());
  std::vector<ContactTool> tools(2);
  tools[0].shape = {ToolShape::Type::Sphere, 0.1, 0.0};
  tools[1].shape = {ToolShape::Type::Capsule, 0.003, 0.03};
  for (ContactTool& t : tools) t.friction = 0.3;
  constexpr int64_t kAdvances = 5, kSubsteps = 8;
  const double t1 = 0.5 * kAdvances * kSubsteps * dt, t2 = 2 * t1;
  const Vec3 sphere = mid + Vec3(0, 0, 0.1), capsule(mid.x(), lo.y() - 0.005, hi.z() + 0.003);
  const std::vector<std::vector<ToolKey>> paths = {
      {{0.0, sphere + Vec3(0, 0, 2e-4), Vec3::UnitZ()},
       {t1, sphere - Vec3(0, 0, 1e-3), Vec3::UnitZ()},
       {t2, sphere + Vec3(1e-3, 0, -1e-3), Vec3::UnitZ()}},
      {{0.0, capsule + Vec3(0, 0, 5e-4), Vec3::UnitY()},
       {t1, capsule - Vec3(0, 0, 1.5e-3), Vec3::UnitY()},
       {t2, capsule + Vec3(2e-3, 0, -1.5e-3), Vec3(0.4, 0.9, 0).normalized()}}};
  GpuSolverOptions options;
  options.contact_in_force = in_force;
  GpuSolver gpu(ctx, set, scene.simulation.gravity, options);
  gpu.set_tearing(true);
  gpu.set_tools(tools);
  PlateRun out;
  for (int64_t a = 0; a < kAdvances; ++a) {
    std::vector<ToolMotion> motion;
    for (int64_t s = a * kSubsteps; s < (a + 1) * kSubsteps; ++s)
      for (const std::vector<ToolKey>& path : paths)
        motion.push_back({pose_at(path, double(s) * dt), pose_at(path, double(s + 1) * dt)});
    gpu.set_tool_motion(motion);
    gpu.advance(kSubsteps, dt);
    const std::vector<ToolContactSample> felt = gpu.tool_samples();
    EXPECT_EQ(felt.size(), size_t(kSubsteps) * tools.size());
    out.samples.insert(out.samples.end(), felt.begin(), felt.end());
    out.candidates = std::max(out.candidates, gpu.contact_candidates());
  }
  out.state = gpu.read_state(false);
  for (const PassTime& t : gpu.profile(2, dt))
    out.rows_timed = out.rows_timed || t.name == "contact: rows";
  return out;
}

TEST_F(GpuSolverTest, ContactRowsOfManyCandidatesAndToolsGiveToolContactsSamples) {
  Scene scene = lattice_scene(70, 70, 3, tissue(5e4, 0.3, 20.0));
  const double bottom = scene.objects[0].shape.min.z();
  scene.objects[0].fixed.push_back(box_shape(Vec3::Constant(-1), Vec3(1, 1, bottom + 1e-4)));
  scene.simulation.gravity = Vec3(0, 0, -9.81);
  const PhyxelSet set = sample_scene(scene);
  const PlateRun rows = press_plate(ctx(), scene, set, true);
  const PlateRun apart = press_plate(ctx(), scene, set, false);
  EXPECT_TRUE(rows.rows_timed);
  EXPECT_FALSE(apart.rows_timed);
  EXPECT_GT(rows.candidates, size_t{64 * 64});
  EXPECT_EQ(rows.candidates, apart.candidates);
  ASSERT_EQ(rows.samples.size(), apart.samples.size());
  uint32_t contacts[2] = {0, 0};
  for (size_t k = 0; k < rows.samples.size(); ++k) {
    const ToolContactSample &a = rows.samples[k], &b = apart.samples[k];
    EXPECT_EQ(a.force, b.force) << "sample " << k;
    EXPECT_EQ(a.contacts, b.contacts) << "sample " << k;
    EXPECT_EQ(a.axial_min, b.axial_min) << "sample " << k;
    EXPECT_EQ(a.axial_max, b.axial_max) << "sample " << k;
    contacts[k % 2] = std::max(contacts[k % 2], a.contacts);
  }
  std::printf("[ rows     ] %zu candidates, at most %u and %u contacts\n", rows.candidates,
              contacts[0], contacts[1]);
  EXPECT_GT(contacts[0], 64u) << "the sphere's contacts fit one partial";
  EXPECT_GT(contacts[1], 0u) << "the capsule touched nothing";
  EXPECT_EQ(rows.state.displacement, apart.state.displacement);
  EXPECT_EQ(rows.state.velocity, apart.state.velocity);
  EXPECT_EQ(rows.state.contact, apart.state.contact);
}

}  // namespace
}  // namespace phyxel::gpu::test
