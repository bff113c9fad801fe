// Bodies too small or too thin for their spacing: every phyxel needs kMinMlsNeighbours (4)
// neighbours within the support radius, not all in one plane, so an object needs at least 5
// phyxels; sampling refuses anything less with one line naming the object, its size, the
// phyxels it got and the spacing it needs. The smallest bodies it accepts run finite.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "engine/run/simulation.h"
#include "engine/solver/solver.h"
#include "tests/sampling/sampling_helpers.h"

namespace phyxel::test {
namespace {

std::string sampling_error(const Scene& scene) {
  try {
    sample_scene(scene);
  } catch (const SceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no SceneError";
  return {};
}

void expect_parts(const std::string& msg, std::initializer_list<std::string> parts) {
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  for (const std::string& part : parts)
    EXPECT_NE(msg.find(part), std::string::npos) << "no \"" << part << "\" in: " << msg;
}

TEST(SmallBody, BoxSmallerThanItsSpacingIsRefusedWithTheSpacingItNeeds) {
  const std::string msg =
      sampling_error(scene_of({object("speck", box(Vec3::Zero(), Vec3::Constant(1e-4)), 0.002)}));
  EXPECT_EQ(
      msg.rfind("test_scene.json: objects[0] \"speck\" (box 0.1 mm across): samples to 1 phyxel "
                "with spacing 0.002 m; it needs at least 5 phyxels, each with 4 neighbours "
                "within the support radius (0.004 m) not all in one plane, for its MLS moment "
                "matrix to be invertible",
                0),
      0u)
      << msg;
  expect_parts(msg, {"use a spacing of at most 0.0001 m (objects[0].spacing)"});
}

TEST(SmallBody, TwoOrFourPhyxelsAreRefusedToo) {
  // 2 phyxels along x; then 2 x 2 in one plane.
  expect_parts(
      sampling_error(scene_of({object("rod", box(Vec3::Zero(), Vec3(0.002, 1e-4, 1e-4)), 0.002)})),
      {"objects[0] \"rod\" (box 2 x 0.1 x 0.1 mm): samples to 2 phyxels", "at least 5 phyxels",
       "at most 0.0001 m"});
  expect_parts(sampling_error(
                   scene_of({object("tile", box(Vec3::Zero(), Vec3(0.002, 0.002, 1e-4)), 0.002)})),
               {"samples to 4 phyxels", "at least 5 phyxels", "at most 0.0001 m"});
}

TEST(SmallBody, ThinPlateIsRefusedNamingAPhyxelWhoseNeighboursAreInOnePlane) {
  const std::string msg = sampling_error(
      scene_of({object("block", box(Vec3::Zero(), Vec3::Constant(0.01)), 0.0025),
                object("sheet", box(Vec3(0, 0, 0.02), Vec3(0.02, 0.02, 0.0201)), 0.002)}));
  expect_parts(
      msg, {"test_scene.json: objects[1] \"sheet\" (box 20 x 20 x 0.1 mm): samples to 121 phyxels "
            "with spacing 0.002 m, but the phyxel at (0, 0, 0.02) m has 3 neighbours, "
            "all in one plane",
            "no stiffness across", "use a spacing of at most 0.0001 m (objects[1].spacing)"});
}

TEST(SmallBody, SphereAndEllipsoidSmallerThanTheirSpacing) {
  expect_parts(
      sampling_error(scene_of({object("ball", sphere(Vec3::Zero(), 0.0015), 0.002)})),
      {"objects[0] \"ball\" (sphere of radius 1.5 mm): samples to 1 phyxel", "at most 0.0015 m"});
  expect_parts(sampling_error(scene_of(
                   {object("lens", ellipsoid(Vec3::Zero(), Vec3(0.01, 0.01, 0.001)), 0.002)})),
               {"objects[0] \"lens\" (ellipsoid of radii 10 x 10 x 1 mm)", "all in one plane",
                "at most 0.001 m"});
}

TEST(SmallBody, ALargerSupportRadiusDoesNotRescueAPlane) {
  ObjectDesc sheet = object("sheet", box(Vec3::Zero(), Vec3(0.02, 0.02, 1e-4)), 0.002);
  sheet.support_radius = 0.01;
  expect_parts(sampling_error(scene_of({sheet})), {"all in one plane", "(0.01 m)"});
}

// The smallest bodies sampling accepts at their spacing: a box whose shortest side is the
// spacing (2 x 2 x 2 phyxels), a sphere whose radius is the spacing (its centre and 6 around
// it), both clamped at the bottom and sagging under gravity, and a free sphere of radius 1.5
// spacings (19 phyxels) thrown without gravity, which must move as a rigid body (every phyxel
// displaced by v t: its fits see no strain). Each runs finite for 2000 steps at the stable time
// step. (Under gravity the free sphere would fall faster than sound in this soft material
// within the 2000 steps, which the run loop rightly calls a runaway.)
TEST(SmallBody, SmallestAcceptedBodiesRunFinite) {
  const double s = 0.002;
  std::vector<Scene> scenes;
  scenes.push_back(scene_of({object("cube", box(Vec3::Zero(), Vec3::Constant(s)), s)}));
  scenes.push_back(scene_of({object("ball", sphere(Vec3::Zero(), s), s)}));
  scenes.push_back(scene_of({object("drop", sphere(Vec3::Zero(), 1.5 * s), s)}));
  scenes[0].objects[0].fixed.push_back(box(Vec3::Constant(-1), Vec3(1, 1, 0.5 * s)));
  scenes[1].objects[0].fixed.push_back(box(Vec3::Constant(-1), Vec3(1, 1, -0.5 * s)));
  scenes[2].objects[0].initial_velocity = Vec3(0.01, 0, 0.02);
  const size_t counts[] = {8, 7, 19};
  for (size_t c = 0; c < scenes.size(); ++c) {
    Scene& scene = scenes[c];
    scene.simulation.gravity = c < 2 ? Vec3(0, 0, -9.81) : Vec3::Zero();
    const PhyxelSet set = sample_scene(scene);
    EXPECT_EQ(set.size(), counts[c]);
    scene.simulation.dt = plan_time_step(scene, set).dt_stable;
    scene.simulation.steps = 2000;
    auto solver = make_cpu_solver(set, scene.simulation.gravity, 1);
    RunOptions options;
    options.steps = scene.simulation.steps;
    const RunResult r = run_simulation(scene, set, *solver, options);
    EXPECT_FALSE(r.non_finite) << c << " at step " << r.non_finite_step;
    EXPECT_FALSE(r.unstable) << c;
    EXPECT_EQ(r.steps_done, 2000) << c;
    const PointState state = solver->read_state(false);
    for (const Vec3& u : state.displacement) {
      ASSERT_TRUE(u.allFinite()) << c;
      if (c < 2) {
        EXPECT_LT(u.norm(), s) << c;  // clamped: sags, does not fall
      } else {
        const Vec3 moved = scene.objects[0].initial_velocity * (2000 * scene.simulation.dt);
        EXPECT_LT((u - moved).norm(), 1e-9 * moved.norm()) << u.transpose();
      }
    }
  }
}

}  // namespace
}  // namespace phyxel::test
