// The `render.backdrop` and `render.instruments` keys: a full parse with every key, the
// defaults, and one SceneError line "FILE: JSON.PATH: problem; allowed ..." per invalid value.
// Each error test starts from the shipped demo with a valid backdrop added and breaks one thing.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "engine/scene/scene.h"
#include "tests/scene/scene_error_helpers.h"

namespace phyxel {
namespace {

using nlohmann::json;
using namespace scene_test;

json with_backdrop() {
  json j = demo();
  j["render"]["backdrop"] = json::parse(R"([
    {"name": "drape", "look": "drape", "spacing": 0.01, "colour": [0.2, 0.5, 0.55],
     "shape": {"type": "box", "min": [-0.3, -0.3, -0.02], "max": [0.3, 0.3, -0.01]},
     "hole": {"type": "sphere", "center": [0, 0, 0], "radius": 0.05}},
    {"name": "skull", "look": "bone", "spacing": 0.002,
     "shape": {"type": "ellipsoid", "center": [0, 0, -0.05], "radii": [0.08, 0.1, 0.09]},
     "within": {"type": "box", "min": [-0.05, -0.05, 0], "max": [0.05, 0.05, 1]}}
  ])");
  j["render"]["instruments"] = json::parse(R"([
    {"name": "retractor", "shape": {"type": "capsule", "radius": 0.002, "length": 0.05},
     "position": [0, 0.03, 0.04], "axis": [0, 3, 4]}
  ])");
  return j;
}

std::string backdrop_error(const std::function<void(json&)>& edit) {
  json j = with_backdrop();
  edit(j);
  return error_text(j.dump());
}

json& item0(json& j) {
  return j["render"]["backdrop"][0];
}

TEST(SceneBackdrop, ReadsEveryKey) {
  const Scene s = parse_scene(with_backdrop().dump(), kFile);
  ASSERT_EQ(s.render.backdrop.size(), 2u);
  const BackdropItem& drape = s.render.backdrop[0];
  EXPECT_EQ(drape.name, "drape");
  EXPECT_EQ(drape.look, BackdropItem::Look::Drape);
  EXPECT_EQ(drape.shape.type, Shape::Type::Box);
  EXPECT_DOUBLE_EQ(drape.spacing, 0.01);
  EXPECT_TRUE(drape.colour.isApprox(Vec3(0.2, 0.5, 0.55)));
  ASSERT_TRUE(drape.hole.has_value());
  EXPECT_EQ(drape.hole->type, Shape::Type::Sphere);
  EXPECT_DOUBLE_EQ(drape.hole->radius, 0.05);
  const BackdropItem& skull = s.render.backdrop[1];
  EXPECT_EQ(skull.look, BackdropItem::Look::Bone);
  EXPECT_FALSE(skull.hole.has_value());
  EXPECT_FALSE(drape.within.has_value());
  ASSERT_TRUE(skull.within.has_value());
  EXPECT_EQ(skull.within->type, Shape::Type::Box);
  EXPECT_GT(skull.colour.minCoeff(), 0.5);  // the bone look's default: pale
  ASSERT_EQ(s.render.instruments.size(), 1u);
  const InstrumentDrawable& r = s.render.instruments[0];
  EXPECT_EQ(r.name, "retractor");
  EXPECT_EQ(r.shape.type, ToolShape::Type::Capsule);
  EXPECT_TRUE(r.pose.axis.isApprox(Vec3(0, 0.6, 0.8)));  // normalised
}

TEST(SceneBackdrop, AbsentMeansNone) {
  const Scene s = parse_scene(demo().dump(), kFile);
  EXPECT_TRUE(s.render.backdrop.empty());
  EXPECT_TRUE(s.render.instruments.empty());
}

TEST(SceneBackdrop, UnknownLook) {
  expect_error(backdrop_error([](json& j) { item0(j)["look"] = "velvet"; }),
               "render.backdrop[0].look", {"velvet", "drape", "skin", "bone", "tissue"});
}

TEST(SceneBackdrop, NonPositiveSpacing) {
  expect_error(backdrop_error([](json& j) { item0(j)["spacing"] = 0; }),
               "render.backdrop[0].spacing", {"spacing > 0"});
  expect_error(backdrop_error([](json& j) { item0(j)["spacing"] = -0.01; }),
               "render.backdrop[0].spacing", {"spacing > 0"});
}

TEST(SceneBackdrop, SpacingTooFineForTheShape) {
  expect_error(backdrop_error([](json& j) { item0(j)["spacing"] = 1e-5; }),
               "render.backdrop[0].spacing", {"splats"});
}

TEST(SceneBackdrop, BadColour) {
  expect_error(backdrop_error([](json& j) {
                 item0(j)["colour"] = {0.2, 1.5, 0.1};
               }),
               "render.backdrop[0].colour[1]", {"1.5"});
  expect_error(backdrop_error([](json& j) {
                 item0(j)["colour"] = {0.2, 0.5};
               }),
               "render.backdrop[0].colour", {});
  expect_error(backdrop_error([](json& j) { item0(j)["colour"] = "green"; }),
               "render.backdrop[0].colour", {});
}

TEST(SceneBackdrop, MissingAndUnknownKeys) {
  expect_error(backdrop_error([](json& j) { item0(j).erase("shape"); }), "render.backdrop[0].shape",
               {"missing", "shape"});
  expect_error(backdrop_error([](json& j) { item0(j)["texture"] = "x.png"; }),
               "render.backdrop[0].texture", {"unknown key", "within"});
  expect_error(backdrop_error([](json& j) {
                 item0(j)["hole"] = {{"type", "cone"}};
               }),
               "render.backdrop[0].hole.type", {"cone"});
  expect_error(backdrop_error([](json& j) { j["render"]["backdrop"] = json::object(); }),
               "render.backdrop", {"array"});
}

TEST(SceneBackdrop, DuplicateName) {
  expect_error(backdrop_error([](json& j) { j["render"]["backdrop"][1]["name"] = "drape"; }),
               "render.backdrop[1].name", {"duplicate", "drape"});
}

TEST(SceneBackdrop, BadInstrument) {
  expect_error(backdrop_error([](json& j) {
                 j["render"]["instruments"][0]["axis"] = {0, 0, 0};
               }),
               "render.instruments[0].axis", {"zero"});
  expect_error(
      backdrop_error([](json& j) { j["render"]["instruments"][0]["shape"]["radius"] = 0; }),
      "render.instruments[0].shape.radius", {"radius > 0"});
}

}  // namespace
}  // namespace phyxel
