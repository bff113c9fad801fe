// Out-of-range values, degenerate shapes, unusable support radii, scenes too big for memory,
// missing meshes: one SceneError line "FILE: JSON.PATH: problem; allowed ..." each.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "engine/scene/scene.h"
#include "tests/scene/scene_error_helpers.h"

namespace phyxel {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using namespace scene_test;

// --- materials ---

TEST(SceneRanges, YoungZero) {
  const std::string msg = error_with([](json& j) { material0(j)["young"] = 0; });
  expect_error(msg, "objects[0].material.young",
               {"0 is out of range", "allowed 0 < young <= 1000000000000 (Pa)"});
}

TEST(SceneRanges, YoungNegative) {
  const std::string msg = error_with([](json& j) { material0(j)["young"] = -5e3; });
  expect_error(msg, "objects[0].material.young", {"-5000 is out of range", "0 < young"});
}

TEST(SceneRanges, PoissonAtOneHalf) {
  const std::string msg = error_with([](json& j) { material0(j)["poisson"] = 0.5; });
  EXPECT_EQ(msg, std::string(kFile) +
                     ": objects[0].material.poisson: 0.5 is out of range; allowed -1 < poisson "
                     "< 0.5");
}

TEST(SceneRanges, PoissonAtMinusOne) {
  const std::string msg = error_with([](json& j) { material0(j)["poisson"] = -1; });
  expect_error(msg, "objects[0].material.poisson", {"-1 is out of range", "-1 < poisson < 0.5"});
}

TEST(SceneRanges, DensityZero) {
  const std::string msg = error_with([](json& j) { material0(j)["density"] = 0; });
  expect_error(msg, "objects[0].material.density",
               {"out of range", "1 <= density <= 100000 (kg/m^3)"});
}

TEST(SceneRanges, DampingNegative) {
  const std::string msg = error_with([](json& j) { material0(j)["damping"] = -0.1; });
  expect_error(msg, "objects[0].material.damping", {"-0.1 is out of range", "damping >= 0 (1/s)"});
}

TEST(SceneRanges, HourglassNegative) {
  const std::string msg = error_with([](json& j) { material0(j)["hourglass"] = -1; });
  expect_error(msg, "objects[0].material.hourglass", {"out of range", "hourglass >= 0"});
}

TEST(SceneRanges, VolumeStiffnessNegative) {
  const std::string msg = error_with([](json& j) { material0(j)["volume_stiffness"] = -1; });
  expect_error(msg, "objects[0].material.volume_stiffness",
               {"out of range", "volume_stiffness >= 0 (Pa)"});
}

TEST(SceneRanges, InclusionPoissonOutOfRange) {
  const std::string msg =
      error_with([](json& j) { object0(j)["inclusions"][0]["material"]["poisson"] = 0.7; });
  expect_error(msg, "objects[0].inclusions[0].material.poisson",
               {"0.7 is out of range", "-1 < poisson < 0.5"});
}

// --- simulation and output ---

TEST(SceneRanges, DtZero) {
  const std::string msg = error_with([](json& j) { j["simulation"]["dt"] = 0; });
  expect_error(msg, "simulation.dt", {"0 is out of range", "dt > 0 (s)"});
}

TEST(SceneRanges, StepsNegative) {
  const std::string msg = error_with([](json& j) { j["simulation"]["steps"] = -1; });
  expect_error(msg, "simulation.steps", {"-1 is out of range", "steps >= 0"});
}

TEST(SceneRanges, CourantZero) {
  const std::string msg = error_with([](json& j) { j["simulation"]["courant"] = 0; });
  expect_error(msg, "simulation.courant", {"out of range", "0 < courant <= 1"});
}

TEST(SceneRanges, CourantAboveOne) {
  const std::string msg = error_with([](json& j) { j["simulation"]["courant"] = 1.5; });
  expect_error(msg, "simulation.courant", {"1.5 is out of range", "0 < courant <= 1"});
}

TEST(SceneRanges, KineticEnergyBoundZero) {
  const std::string msg =
      error_with([](json& j) { j["simulation"]["until_rest"]["kinetic_energy_below"] = 0; });
  expect_error(msg, "simulation.until_rest.kinetic_energy_below",
               {"out of range", "kinetic_energy_below > 0 (J)"});
}

TEST(SceneRanges, ForStepsZero) {
  const std::string msg =
      error_with([](json& j) { j["simulation"]["until_rest"]["for_steps"] = 0; });
  expect_error(msg, "simulation.until_rest.for_steps", {"0 is out of range", "for_steps >= 1"});
}

TEST(SceneRanges, OutputEveryNegative) {
  const std::string msg = error_with([](json& j) { j["output"]["every"] = -10; });
  expect_error(msg, "output.every", {"-10 is out of range", "every >= 0"});
}

// --- objects and shapes ---

TEST(SceneRanges, SpacingZero) {
  const std::string msg = error_with([](json& j) { object0(j)["spacing"] = 0; });
  expect_error(msg, "objects[0].spacing", {"0 is out of range", "spacing > 0 (m)"});
}

TEST(SceneRanges, BoxMinNotBelowMax) {
  const std::string msg = error_with([](json& j) { object0(j)["shape"]["max"][1] = -0.01; });
  expect_error(msg, "objects[0].shape.max",
               {"max[1] = -0.01 is not greater than min[1] = -0.01", "min < max on every axis"});
}

TEST(SceneRanges, FixedRegionBoxInverted) {
  const std::string msg = error_with([](json& j) { object0(j)["fixed"][0]["min"][0] = 2; });
  expect_error(msg, "objects[0].fixed[0].max", {"max[0] = 0.0005", "min < max"});
}

TEST(SceneRanges, SphereRadiusZero) {
  const std::string msg =
      error_with([](json& j) { object0(j)["inclusions"][0]["shape"]["radius"] = 0; });
  expect_error(msg, "objects[0].inclusions[0].shape.radius",
               {"0 is out of range", "radius > 0 (m)"});
}

TEST(SceneRanges, EllipsoidRadiusNegative) {
  const std::string msg = error_with([](json& j) {
    object0(j)["shape"] = {
        {"type", "ellipsoid"}, {"center", {0, 0, 0}}, {"radii", {0.1, -0.1, 0.1}}};
  });
  expect_error(msg, "objects[0].shape.radii[1]", {"-0.1 is out of range", "radii[1] > 0 (m)"});
}

TEST(SceneRanges, LoadRegionSphereRadiusNegative) {
  const std::string msg = error_with([](json& j) {
    object0(j)["loads"][0]["region"] = {{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", -1}};
  });
  expect_error(msg, "objects[0].loads[0].region.radius", {"out of range", "radius > 0"});
}

TEST(SceneRanges, MeshScaleZero) {
  const std::string msg = error_with([](json& j) {
    object0(j)["shape"] = {{"type", "mesh"}, {"path", "organ.obj"}, {"scale", 0}};
  });
  expect_error(msg, "objects[0].shape.scale", {"0 is out of range", "scale > 0"});
}

TEST(SceneRanges, MissingMeshFileNamesTheShapePath) {
  const std::string msg = error_with([](json& j) {
    object0(j)["shape"] = {{"type", "mesh"}, {"path", "no_such_organ.obj"}};
  });
  expect_error(msg, "objects[0].shape.path",
               {"mesh file \"scenes/no_such_organ.obj\" does not exist",
                "relative to the scene file's folder (scenes)"});
}

TEST(SceneRanges, SupportRadiusTooSmallReportsTheMinimum) {
  // spacing 0.0025: a corner phyxel has 3 neighbours up to sqrt(2) * 0.0025 = 0.00353553.
  const std::string msg = error_with([](json& j) { object0(j)["support_radius"] = 0.0035; });
  expect_error(msg, "objects[0].support_radius",
               {"0.0035 gives a phyxel at a lattice corner 3 neighbours", "interior phyxel 6",
                "allowed support_radius > 0.00353553", "sqrt(2) * spacing"});
}

TEST(SceneRanges, SupportRadiusEqualToSpacingHasNoNeighbours) {
  const std::string msg = error_with([](json& j) { object0(j)["support_radius"] = 0.0025; });
  expect_error(msg, "objects[0].support_radius",
               {"lattice corner 0 neighbours", "support_radius > 0.00353553"});
}

TEST(SceneRanges, SpacingTooSmallForMemory) {
  const std::string msg = error_with([](json& j) {
    object0(j)["shape"] = {{"type", "box"}, {"min", {0, 0, 0}}, {"max", {1, 1, 1}}};
    object0(j)["spacing"] = 1e-5;
    object0(j).erase("support_radius");  // the default 2 x spacing: about 1690 bytes a phyxel
  });
  expect_error(msg, "objects[0].spacing",
               {"1e-05 gives about 1e+15 phyxels", "1.69", "at about 1690 bytes each", "memory",
                "a larger spacing is needed: spacing > "});
}

TEST(SceneRanges, MemoryCheckBlamesTheLargestObject) {
  const std::string msg = error_with([](json& j) {
    json big = object0(j);
    big["name"] = "big";
    big["shape"] = {{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1}};
    big["spacing"] = 1e-5;
    big.erase("support_radius");
    j["objects"].push_back(big);
  });
  expect_error(msg, "objects[1].spacing", {"8e+15 phyxels", "a larger spacing is needed"});
}

TEST(SceneRanges, LoadUntilNotAfterFrom) {
  expect_error(error_with([](json& j) {
                 object0(j)["loads"][0]["from"] = 0.2;
                 object0(j)["loads"][0]["until"] = 0.1;
               }),
               "objects[0].loads[0].until", {"0.1"});
}

TEST(SceneRanges, LoadFromNegative) {
  expect_error(error_with([](json& j) { object0(j)["loads"][0]["from"] = -1; }),
               "objects[0].loads[0].from", {"-1"});
}

TEST(SceneRanges, SleepEnergyNotPositive) {
  expect_error(error_with([](json& j) {
                 j["simulation"]["sleep"] = {{"kinetic_energy_below", 0}};
               }),
               "simulation.sleep.kinetic_energy_below", {"0"});
}

TEST(SceneParseTimedLoads, WindowAndSleepAreRead) {
  json j = demo();
  object0(j)["loads"][0]["from"] = 0.1;
  object0(j)["loads"][0]["until"] = 0.3;
  j["simulation"]["sleep"] = {{"kinetic_energy_below", 1e-9}, {"for_steps", 50}};
  const Scene s = parse_scene(j.dump(), kFile);
  EXPECT_DOUBLE_EQ(s.objects[0].loads[0].from, 0.1);
  EXPECT_DOUBLE_EQ(s.objects[0].loads[0].until, 0.3);
  EXPECT_TRUE(std::isinf(s.objects[0].loads.at(0).until) == false);
  EXPECT_TRUE(s.simulation.sleep.enabled);
  EXPECT_DOUBLE_EQ(s.simulation.sleep.kinetic_energy_below, 1e-9);
  EXPECT_EQ(s.simulation.sleep.for_steps, 50);
  j = demo();
  const Scene plain = parse_scene(j.dump(), kFile);
  EXPECT_TRUE(std::isinf(plain.objects[0].loads[0].until));
  EXPECT_FALSE(plain.simulation.sleep.enabled);
}

}  // namespace
}  // namespace phyxel
