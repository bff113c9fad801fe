// A thick probe ploughing through tissue at the spacing where `phyxel bench --tearing`'s intact
// 97 336-phyxel box turned non-finite (docs/performance-log.md, "Tearing", note a): a part of that
// box, the same lattice, material, probe and path, on the CPU reference.
#include <gtest/gtest.h>

#include "../physics/physics_fixtures.h"
#include "engine/run/simulation.h"

namespace phyxel {
namespace {

// The bench box's lattice (0.1 m in 45 spacings, E 100 kPa, nu 0.3, damping 1, clamped base)
// cut to 26 x 18 x 26 spacings around the probe's path; the probe is bench --tearing's: a
// vertical capsule of radius 5 mm (2.25 spacings), its tip 3 cm above the base, crossing along
// x at 0.5 m/s with friction 0.2.
Scene ploughed_box() {
  const double s = 0.1 / 45;
  Scene scene = test::box_scene(Vec3(0, 14 * s, 0), Vec3(26 * s, 32 * s, 26 * s), s,
                                test::tissue(1e5, 0.3, 1.0));
  scene.objects[0].fixed.push_back(test::box_shape(Vec3(-1, -1, -1), Vec3(1, 1, 0.5 * s)));
  scene.simulation.gravity = Vec3(0, 0, -9.81);
  scene.simulation.dt = 9.57e-5;  // just below the stable step, as the bench's
  scene.simulation.steps = 1000;  // the probe crosses 4.8 cm: to x = 0.043 of the box's 0.058
  ToolDesc probe;
  probe.name = "probe";
  probe.shape.type = ToolShape::Type::Capsule;
  probe.shape.radius = 0.005;
  probe.shape.length = 0.09;
  probe.path = {{0.0, Vec3(-0.005, 0.0503, 0.03), Vec3::UnitZ()},
                {0.22, Vec3(0.105, 0.0503, 0.03), Vec3::UnitZ()}};
  probe.friction = 0.2;
  scene.tools.push_back(probe);
  return scene;
}

// What a thick tool does to tissue it ploughs through (docs/decisions.md, "A thick tool through
// tissue that cannot tear"). Without tear_stress the tissue cannot give way: the phyxels the
// probe's tip carries along (phyxel 6912 of this box, on the front face 1.1 mm below the tip) are
// inverted by step 160 and their neighbourhood is stretched without bound (the largest singular
// value of F 1.2 at step 160, 3.5 at 580). The MLS gradient of a neighbourhood turned inside out
// no longer describes it, and St Venant-Kirchhoff, corotated and stable neo-Hookean laws all run
// away (docs/performance-log.md, "Tearing", note a). The run stops there and names the probe, whose
// crossing it could not follow (its message then says to slow the tool or give the material a
// tear_stress). With the bench's tear_stress (12 kPa) the tissue tears ahead of the probe and
// the probe crosses the box with every phyxel finite and slower than the wave speed.
struct Ploughed {
  RunResult result;
  size_t torn = 0;  // pairs severed, all torn (no scalpel)
};

Ploughed plough(const Scene& scene) {
  const PhyxelSet set = sample_scene(scene);
  const std::unique_ptr<Solver> solver = make_cpu_solver(set, scene.simulation.gravity, 1);
  RunOptions options;
  options.steps = scene.simulation.steps;
  Ploughed out;
  out.result = run_simulation(scene, set, *solver, options);
  out.torn = solver->cutting()->severed_pairs();
  return out;
}

TEST(ProbePloughing, TissueThatCannotTearStopsTheRunNamingTheProbe) {
  const Ploughed ploughed = plough(ploughed_box());
  const RunResult& result = ploughed.result;
  EXPECT_EQ(ploughed.torn, 0u);
  ASSERT_TRUE(result.unstable || result.non_finite) << "the probe crossed tissue that cannot tear";
  EXPECT_LT(result.steps_done, 1000);
  if (result.unstable) {
    EXPECT_EQ(result.unstable_tool, 0) << "phyxel " << result.unstable_phyxel;
  } else {
    EXPECT_EQ(result.non_finite_tool, 0) << "step " << result.non_finite_step;
    EXPECT_GT(result.non_finite_tool_contacts, 0u);
  }
}

TEST(ProbePloughing, ThickProbeThroughTissueThatTearsStaysFiniteAndSubsonic) {
  Scene scene = ploughed_box();
  scene.objects[0].material.tear_stress = 12e3;  // phyxel bench --tearing's default
  const Ploughed ploughed = plough(scene);
  const RunResult& result = ploughed.result;
  EXPECT_FALSE(result.non_finite) << "step " << result.non_finite_step;
  EXPECT_FALSE(result.unstable) << "phyxel " << result.unstable_phyxel << " at step "
                                << result.unstable_step << ", " << result.unstable_speed << " m/s";
  EXPECT_EQ(result.steps_done, scene.simulation.steps);
  ASSERT_EQ(result.tools.size(), 1u);
  EXPECT_GT(result.tools[0].max_contacts, 0u) << "the probe never touched the tissue";
  EXPECT_GT(ploughed.torn, 0u) << "the tissue never gave way";
}

// A run that runs away names the tool beside the runaway phyxel (RunResult::unstable_tool,
// summary.json's unstable_at.nearest_tool, and `phyxel run`'s message, which then says to slow
// the tool or let the tissue tear), and no tool where the runaway is away from every tool; one
// that turns non-finite names the tool in contact since the check before (non_finite_tool). A
// step twice the stable one (courant 2, checked every step) drives a clamped 2 cm box unstable
// where it moves: under a sphere pressing into its top with no gravity, everywhere under gravity
// with the sphere 5 cm away.
TEST(ProbePloughing, ARunawayBesideAToolNamesIt) {
  auto scene_with = [](const Vec3& sphere_start, const Vec3& gravity) {
    const double s = 0.002;
    Scene scene =
        test::box_scene(Vec3::Zero(), Vec3(0.02, 0.02, 0.02), s, test::tissue(1e5, 0.3, 1.0));
    scene.objects[0].fixed.push_back(test::box_shape(Vec3(-1, -1, -1), Vec3(1, 1, 0.5 * s)));
    scene.simulation.gravity = gravity;
    scene.simulation.courant = 2;  // past what the scene reader allows (1)
    scene.simulation.steps = 2000;
    ToolDesc probe;
    probe.name = "sphere";
    probe.shape.type = ToolShape::Type::Sphere;
    probe.shape.radius = 0.003;
    probe.path = {{0.0, sphere_start, Vec3::UnitZ()},
                  {0.02, sphere_start - Vec3(0, 0, 0.004), Vec3::UnitZ()}};
    scene.tools.push_back(probe);
    return scene;
  };
  auto run = [](Scene scene, int64_t check_every = 1) {
    const PhyxelSet set = sample_scene(scene);
    scene.simulation.dt = plan_time_step(scene, set).dt_stable;  // one substep a step
    const std::unique_ptr<Solver> solver = make_cpu_solver(set, scene.simulation.gravity, 1);
    RunOptions options;
    options.steps = scene.simulation.steps;
    options.check_every = check_every;  // 1: the runaway is caught before it turns non-finite
    return run_simulation(scene, set, *solver, options);
  };
  const RunResult pressed = run(scene_with(Vec3(0.01, 0.01, 0.0235), Vec3::Zero()));
  ASSERT_TRUE(pressed.unstable) << "non-finite: " << pressed.non_finite;
  EXPECT_EQ(pressed.unstable_tool, 0);
  EXPECT_LT(pressed.unstable_tool_distance, 0.004);  // within a support radius (4 mm)
  const RunResult away = run(scene_with(Vec3(0.01, 0.01, 0.08), Vec3(0, 0, -9.81)));
  ASSERT_TRUE(away.unstable) << "non-finite: " << away.non_finite;
  EXPECT_EQ(away.unstable_tool, -1);
  // Checked every 100 steps the same runs turn non-finite first: the tool that touched the
  // tissue since the check before is named, and none where no tool touched it.
  const RunResult pressed_late = run(scene_with(Vec3(0.01, 0.01, 0.0235), Vec3::Zero()), 100);
  ASSERT_TRUE(pressed_late.non_finite);
  EXPECT_EQ(pressed_late.non_finite_tool, 0);
  EXPECT_GT(pressed_late.non_finite_tool_contacts, 0u);
  const RunResult away_late = run(scene_with(Vec3(0.01, 0.01, 0.08), Vec3(0, 0, -9.81)), 100);
  ASSERT_TRUE(away_late.non_finite);
  EXPECT_EQ(away_late.non_finite_tool, -1);
}

}  // namespace
}  // namespace phyxel
