// The material key tear_stress (Pa, > 0 and finite; absent: never tears): reading, the
// inclusions' default from the host, Scene::tearing_possible, and one SceneError line for each
// bad value.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "engine/scene/scene.h"
#include "tests/scene/scene_error_helpers.h"

namespace phyxel {
namespace {

using nlohmann::json;
using namespace scene_test;

Scene parsed(const json& j) {
  return parse_scene(j.dump(), kFile);
}

TEST(SceneTearStress, AbsentMeansNothingTears) {
  const Scene scene = parsed(demo());
  ASSERT_FALSE(scene.objects.empty());
  EXPECT_FALSE(scene.objects[0].material.tear_stress);
  EXPECT_FALSE(scene.tearing_possible());
}

TEST(SceneTearStress, ReadOnTheHostAndInheritedByInclusions) {
  json j = demo();
  material0(j)["tear_stress"] = 2500;
  const Scene scene = parsed(j);
  ASSERT_TRUE(scene.objects[0].material.tear_stress);
  EXPECT_EQ(*scene.objects[0].material.tear_stress, 2500);
  ASSERT_FALSE(scene.objects[0].inclusions.empty());
  ASSERT_TRUE(scene.objects[0].inclusions[0].material.tear_stress);  // the host's default
  EXPECT_EQ(*scene.objects[0].inclusions[0].material.tear_stress, 2500);
  EXPECT_TRUE(scene.tearing_possible());
}

TEST(SceneTearStress, AnInclusionAloneMakesTearingPossible) {
  json j = demo();
  object0(j)["inclusions"][0]["material"]["tear_stress"] = 8e3;
  const Scene scene = parsed(j);
  EXPECT_FALSE(scene.objects[0].material.tear_stress);
  ASSERT_TRUE(scene.objects[0].inclusions[0].material.tear_stress);
  EXPECT_EQ(*scene.objects[0].inclusions[0].material.tear_stress, 8e3);
  EXPECT_TRUE(scene.tearing_possible());
}

TEST(SceneTearStress, ZeroIsRefused) {
  const std::string msg = error_with([](json& j) { material0(j)["tear_stress"] = 0; });
  EXPECT_EQ(msg, std::string(kFile) +
                     ": objects[0].material.tear_stress: 0 is out of range; allowed "
                     "tear_stress > 0 (Pa)");
}

TEST(SceneTearStress, NegativeIsRefused) {
  const std::string msg = error_with([](json& j) { material0(j)["tear_stress"] = -1e3; });
  expect_error(msg, "objects[0].material.tear_stress",
               {"-1000 is out of range", "tear_stress > 0 (Pa)"});
}

TEST(SceneTearStress, NotANumberIsRefused) {
  for (const json& bad : {json("1e3"), json(nullptr), json::array({1e3}), json(true)}) {
    const std::string msg = error_with([&](json& j) { material0(j)["tear_stress"] = bad; });
    expect_error(msg, "objects[0].material.tear_stress",
                 {"expected a number", "tear_stress > 0 (Pa)"});
  }
}

TEST(SceneTearStress, InfinityIsRefused) {
  // JSON has no infinity; a number too large for a double is the way to write one.
  const std::string msg = error_text(
      R"({"simulation": {"dt": 1e-4, "steps": 1}, "objects": [{"material": {"tear_stress": 1e400}}]})");
  expect_error(msg, "objects[0].material.tear_stress", {"1e400", "not a finite number", "finite"});
}

TEST(SceneTearStress, InclusionValueIsChecked) {
  const std::string msg =
      error_with([](json& j) { object0(j)["inclusions"][0]["material"]["tear_stress"] = -5; });
  expect_error(msg, "objects[0].inclusions[0].material.tear_stress",
               {"-5 is out of range", "tear_stress > 0 (Pa)"});
}

TEST(SceneTearStress, MisspelledKeyIsNamed) {
  const std::string msg = error_with([](json& j) { material0(j)["tear_stres"] = 1e3; });
  expect_error(msg, "objects[0].material.tear_stres",
               {"unknown key", "did you mean \"tear_stress\"?", "hourglass, tear_stress"});
}

}  // namespace
}  // namespace phyxel
