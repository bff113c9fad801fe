// The `tools` key: a full parse with every key, the defaults, and one SceneError line
// "FILE: JSON.PATH: problem; allowed ..." per invalid value. Each error test starts from the
// shipped demo with two valid tools added and breaks one thing.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "engine/scene/scene.h"
#include "tests/scene/scene_error_helpers.h"

namespace phyxel {
namespace {

using nlohmann::json;
using namespace scene_test;

// A path-driven capsule with every key but coupling, and a haptic sphere with its coupling.
json two_tools() {
  return json::parse(R"([
    {"name": "probe", "type": "probe", "shape": {"type": "capsule", "radius": 0.002, "length": 0.03},
     "path": [{"t": 0.0, "position": [0, 0, 0.06], "axis": [0, 0, 2]},
              {"t": 0.5, "position": [0, 0, 0.045], "axis": [3, 0, 4]}],
     "friction": 0.2, "control": "path"},
    {"name": "hand", "type": "probe", "shape": {"type": "sphere", "radius": 0.004},
     "path": [{"t": 0.25, "position": [0.01, 0.02, 0.03]}],
     "control": "haptic",
     "coupling": {"stiffness": 500, "damping": 0.5, "mass": 0.05, "max_force": 4}}
  ])");
}

json with_tools() {
  json j = demo();
  j["tools"] = two_tools();
  return j;
}

std::string tools_error(const std::function<void(json&)>& edit) {
  json j = with_tools();
  edit(j);
  return error_text(j.dump());
}

json& tool0(json& j) {
  return j["tools"][0];
}

// One broken value each: the path of the error and the parts of its message.
struct ErrorCase {
  std::function<void(json&)> edit;
  std::string path;
  std::vector<std::string> parts;
};

void expect_errors(const std::vector<ErrorCase>& cases) {
  for (const ErrorCase& c : cases) {
    SCOPED_TRACE(c.path);
    expect_error(tools_error(c.edit), c.path, c.parts);
  }
}

// --- valid scenes ---

TEST(SceneTools, EveryKeyIsRead) {
  const Scene s = parse_scene(with_tools().dump(), kFile);
  ASSERT_EQ(s.tools.size(), 2u);

  const ToolDesc& probe = s.tools[0];
  EXPECT_EQ(probe.name, "probe");
  EXPECT_EQ(probe.type, ToolDesc::Type::Probe);
  EXPECT_EQ(probe.shape.type, ToolShape::Type::Capsule);
  EXPECT_DOUBLE_EQ(probe.shape.radius, 0.002);
  EXPECT_DOUBLE_EQ(probe.shape.length, 0.03);
  ASSERT_EQ(probe.path.size(), 2u);
  EXPECT_DOUBLE_EQ(probe.path[0].t, 0.0);
  EXPECT_DOUBLE_EQ(probe.path[1].t, 0.5);
  EXPECT_EQ(probe.path[0].position, Vec3(0, 0, 0.06));
  EXPECT_EQ(probe.path[1].position, Vec3(0, 0, 0.045));
  // Axes are stored normalised: [0, 0, 2] -> z, [3, 0, 4] -> [0.6, 0, 0.8].
  EXPECT_NEAR((probe.path[0].axis - Vec3(0, 0, 1)).norm(), 0, 1e-15);
  EXPECT_NEAR((probe.path[1].axis - Vec3(0.6, 0, 0.8)).norm(), 0, 1e-15);
  EXPECT_DOUBLE_EQ(probe.friction, 0.2);
  EXPECT_EQ(probe.control, ToolDesc::Control::Path);

  const ToolDesc& hand = s.tools[1];
  EXPECT_EQ(hand.name, "hand");
  EXPECT_EQ(hand.shape.type, ToolShape::Type::Sphere);
  EXPECT_DOUBLE_EQ(hand.shape.radius, 0.004);
  EXPECT_DOUBLE_EQ(hand.shape.length, 0.0);
  ASSERT_EQ(hand.path.size(), 1u);
  EXPECT_DOUBLE_EQ(hand.path[0].t, 0.25);
  EXPECT_EQ(hand.path[0].position, Vec3(0.01, 0.02, 0.03));
  EXPECT_EQ(hand.control, ToolDesc::Control::Haptic);
  EXPECT_DOUBLE_EQ(hand.coupling.stiffness, 500);
  EXPECT_DOUBLE_EQ(hand.coupling.damping, 0.5);
  EXPECT_DOUBLE_EQ(hand.coupling.mass, 0.05);
  EXPECT_DOUBLE_EQ(hand.coupling.max_force, 4);
}

TEST(SceneTools, Defaults) {
  json j = demo();
  j["tools"] = json::parse(R"([{"name": "p", "type": "probe",
    "shape": {"type": "sphere", "radius": 0.001}, "path": [{"t": 0, "position": [0, 0, 1]}]}])");
  const Scene s = parse_scene(j.dump(), kFile);
  ASSERT_EQ(s.tools.size(), 1u);
  const ToolDesc& t = s.tools[0];
  EXPECT_EQ(t.path[0].axis, Vec3::UnitZ());
  EXPECT_EQ(t.friction, 0.0);
  EXPECT_EQ(t.control, ToolDesc::Control::Path);
  const CouplingSettings defaults;
  EXPECT_EQ(t.coupling.stiffness, defaults.stiffness);
  EXPECT_EQ(t.coupling.damping, defaults.damping);
  EXPECT_EQ(t.coupling.mass, defaults.mass);
  EXPECT_EQ(t.coupling.max_force, defaults.max_force);
  EXPECT_EQ(t.coupling.max_speed, 0.0);  // the scene's, from its tissue
}

// A haptic tool's top speed: its coupling's max_speed, else a tenth of the slowest p-wave speed
// of the scene's objects and inclusions.
TEST(SceneTools, LiveToolSpeedIsItsOwnOrATenthOfTheSlowestWave) {
  json j = with_tools();
  j["objects"][0]["material"] = json::parse(R"({"young": 3000, "poisson": 0.45, "density": 1040})");
  j["objects"][0]["inclusions"] = json::parse(R"([{"name": "soft",
    "shape": {"type": "sphere", "center": [0, 0, 0], "radius": 0.002},
    "material": {"young": 1000, "poisson": 0.45, "density": 1040}}])");
  Scene s = parse_scene(j.dump(), kFile);
  const Material& soft = s.objects[0].inclusions[0].material;
  EXPECT_LT(p_wave_speed(soft), p_wave_speed(s.objects[0].material));
  EXPECT_NEAR(p_wave_speed(soft), 1.9098, 1e-4);  // sqrt((lambda + 2 mu) / rho)
  EXPECT_DOUBLE_EQ(live_tool_speed(s, s.tools[1]), 0.1 * p_wave_speed(soft));
  j["tools"][1]["coupling"]["max_speed"] = 0.05;
  s = parse_scene(j.dump(), kFile);
  EXPECT_DOUBLE_EQ(s.tools[1].coupling.max_speed, 0.05);
  EXPECT_DOUBLE_EQ(live_tool_speed(s, s.tools[1]), 0.05);
  EXPECT_EQ(live_tool_speeds(s).size(), s.tools.size());
}

TEST(SceneTools, HapticCouplingKeysDefaultOneByOne) {
  json j = with_tools();
  j["tools"][1]["coupling"] = json::parse(R"({"mass": 0.1})");
  const Scene s = parse_scene(j.dump(), kFile);
  const CouplingSettings defaults;
  EXPECT_EQ(s.tools[1].coupling.mass, 0.1);
  EXPECT_EQ(s.tools[1].coupling.stiffness, defaults.stiffness);
  EXPECT_EQ(s.tools[1].coupling.damping, defaults.damping);
  EXPECT_EQ(s.tools[1].coupling.max_force, defaults.max_force);
}

TEST(SceneTools, NoToolsKeyAndEmptyArrayGiveNoTools) {
  EXPECT_TRUE(parse_scene(demo().dump(), kFile).tools.empty());
  json j = demo();
  j["tools"] = json::array();
  EXPECT_TRUE(parse_scene(j.dump(), kFile).tools.empty());
}

TEST(SceneTools, TinyAndHugeAxesAreNormalised) {
  json j = with_tools();
  tool0(j)["path"][0]["axis"] = {1e-200, 0, 1e-200};
  tool0(j)["path"][1]["axis"] = {0, 1e300, 0};
  const Scene s = parse_scene(j.dump(), kFile);
  EXPECT_NEAR((s.tools[0].path[0].axis - Vec3(1, 0, 1) / std::sqrt(2.0)).norm(), 0, 1e-15);
  EXPECT_NEAR((s.tools[0].path[1].axis - Vec3::UnitY()).norm(), 0, 1e-15);
}

// --- the array and the tool object ---

TEST(SceneToolsErrors, TopLevelKeyListNamesTools) {
  const std::string msg = error_with([](json& j) { j["tool"] = json::array(); });
  expect_error(
      msg, "tool",
      {"unknown key \"tool\"", "did you mean \"tools\"?",
       "allowed keys at the top level: simulation, objects, output, camera, render, tools"});
}

TEST(SceneToolsErrors, ToolsMustBeAnArray) {
  const std::string msg = tools_error([](json& j) { j["tools"] = json::object(); });
  expect_error(msg, "tools", {"expected an array of tool objects", "got an object"});
}

TEST(SceneToolsErrors, UnknownToolKey) {
  const std::string msg = tools_error([](json& j) { tool0(j)["frictoin"] = 0.1; });
  expect_error(msg, "tools[0].frictoin",
               {"unknown key", "did you mean \"friction\"?",
                "allowed keys in tools[0]: name, type, shape, path, friction, control, coupling"});
}

TEST(SceneToolsErrors, NameRequired) {
  const std::string msg = tools_error([](json& j) { tool0(j).erase("name"); });
  expect_error(msg, "tools[0].name", {"missing required key \"name\"", "a non-empty string"});
}

TEST(SceneToolsErrors, NameEmpty) {
  const std::string msg = tools_error([](json& j) { tool0(j)["name"] = ""; });
  expect_error(msg, "tools[0].name", {"empty string", "allowed a non-empty string"});
}

TEST(SceneToolsErrors, NameDuplicate) {
  const std::string msg = tools_error([](json& j) { j["tools"][1]["name"] = "probe"; });
  expect_error(msg, "tools[1].name",
               {"duplicate tool name \"probe\"", "also tools[0].name", "no other tool uses"});
}

// --- type ---

TEST(SceneToolsErrors, TypeRequired) {
  const std::string msg = tools_error([](json& j) { tool0(j).erase("type"); });
  expect_error(msg, "tools[0].type", {"missing required key \"type\"", "\"probe\""});
}

// --- grasper ---

json& make_grasper(json& j) {
  json& t = tool0(j);
  t["type"] = "grasper";
  t["grasp"] = {{"reach", 0.003}, {"from", 0.02}, {"until", 0.3}};
  return t;
}

TEST(SceneTools, GraspKeysAreRead) {
  json j = with_tools();
  make_grasper(j);
  const Scene s = parse_scene(j.dump(), kFile);
  const ToolDesc& t = s.tools[0];
  EXPECT_EQ(t.type, ToolDesc::Type::Grasper);
  EXPECT_DOUBLE_EQ(t.grasp.reach, 0.003);
  EXPECT_TRUE(t.grasp.closed_at(0.02));
  EXPECT_FALSE(t.grasp.closed_at(0.01));
  EXPECT_FALSE(t.grasp.closed_at(0.3));
  EXPECT_FALSE(t.suction.sucks());
  EXPECT_FALSE(s.tools[1].grasp.grasps());  // the other tool does not grasp
  // Without from/until: closed from the start to the end.
  tool0(j)["grasp"].erase("from");
  tool0(j)["grasp"].erase("until");
  const Grasp always = parse_scene(j.dump(), kFile).tools[0].grasp;
  EXPECT_TRUE(always.closed_at(0) && always.closed_at(1e9));
}

TEST(SceneToolsErrors, GraspValuesAreChecked) {
  expect_errors({
      {[](json& j) { make_grasper(j).erase("grasp"); },
       "tools[0].grasp",
       {"missing required key \"grasp\""}},
      {[](json& j) { make_grasper(j)["grasp"].erase("reach"); },
       "tools[0].grasp.reach",
       {"missing required key \"reach\""}},
      {[](json& j) { make_grasper(j)["grasp"]["reach"] = -0.001; },
       "tools[0].grasp.reach",
       {"reach > 0"}},
      {[](json& j) { make_grasper(j)["grasp"]["from"] = -1; },
       "tools[0].grasp.from",
       {"from >= 0"}},
      {[](json& j) { make_grasper(j)["grasp"]["until"] = 0.02; },
       "tools[0].grasp.until",
       {"until = 0.02 is not after from = 0.02"}},
      {[](json& j) { make_grasper(j)["grasp"]["reech"] = 1; },
       "tools[0].grasp.reech",
       {"did you mean \"reach\"?"}},
      {[](json& j) {
         tool0(j)["grasp"] = {{"reach", 0.001}};
       },
       "tools[0].grasp",
       {"\"grasp\" applies only to a grasper"}},
  });
}

// --- suction ---

json& make_aspirator(json& j) {
  json& t = tool0(j);
  t["type"] = "suction";
  t["suction"] = {{"pressure", 20000}, {"reach", 0.004}, {"from", 0.1}, {"until", 0.4}};
  return t;
}

TEST(SceneTools, SuctionKeysAreRead) {
  json j = with_tools();
  make_aspirator(j);
  const Scene s = parse_scene(j.dump(), kFile);
  const ToolDesc& t = s.tools[0];
  EXPECT_EQ(t.type, ToolDesc::Type::Suction);
  EXPECT_DOUBLE_EQ(t.suction.pressure, 20000);
  EXPECT_DOUBLE_EQ(t.suction.reach, 0.004);
  EXPECT_DOUBLE_EQ(t.suction.flow_speed, 0.5);  // the default
  EXPECT_DOUBLE_EQ(t.suction.interval, 0.003);  // the default
  EXPECT_TRUE(t.suction.on_at(0.1));
  EXPECT_FALSE(t.suction.on_at(0.05));
  EXPECT_FALSE(t.suction.on_at(0.4));
  EXPECT_FALSE(s.tools[1].suction.sucks());  // the other tool does not suck
  // Without from/until: on from the start to the end.
  tool0(j)["suction"].erase("from");
  tool0(j)["suction"].erase("until");
  const Suction always = parse_scene(j.dump(), kFile).tools[0].suction;
  EXPECT_TRUE(always.on_at(0) && always.on_at(1e9));
  tool0(j)["suction"]["flow_speed"] = 0.25;
  EXPECT_DOUBLE_EQ(parse_scene(j.dump(), kFile).tools[0].suction.flow_speed, 0.25);
  tool0(j)["suction"]["interval"] = 0.001;
  EXPECT_DOUBLE_EQ(parse_scene(j.dump(), kFile).tools[0].suction.interval, 0.001);
}

TEST(SceneToolsErrors, SuctionValuesAreChecked) {
  expect_errors({
      {[](json& j) { make_aspirator(j).erase("suction"); },
       "tools[0].suction",
       {"missing required key \"suction\""}},
      {[](json& j) { make_aspirator(j)["suction"].erase("pressure"); },
       "tools[0].suction.pressure",
       {"missing required key \"pressure\""}},
      {[](json& j) { make_aspirator(j)["suction"]["pressure"] = 0; },
       "tools[0].suction.pressure",
       {"allowed 0 < pressure <= 1000000 (Pa)"}},
      {[](json& j) { make_aspirator(j)["suction"]["reach"] = -0.001; },
       "tools[0].suction.reach",
       {"reach > 0"}},
      {[](json& j) { make_aspirator(j)["suction"]["flow_speed"] = 0; },
       "tools[0].suction.flow_speed",
       {"allowed 0 < flow_speed <= 100 (m/s)"}},
      {[](json& j) { make_aspirator(j)["suction"]["flow_speed"] = 1e3; },
       "tools[0].suction.flow_speed",
       {"allowed 0 < flow_speed <= 100 (m/s)"}},
      {[](json& j) { make_aspirator(j)["suction"]["interval"] = 0; },
       "tools[0].suction.interval",
       {"allowed 0 < interval <= 1 (s)"}},
      {[](json& j) { make_aspirator(j)["suction"]["until"] = 0.05; },
       "tools[0].suction.until",
       {"until = 0.05 is not after from = 0.1"}},
      {[](json& j) { make_aspirator(j)["suction"]["presure"] = 1; },
       "tools[0].suction.presure",
       {"did you mean \"pressure\"?"}},
      {[](json& j) {
         tool0(j)["suction"] = {{"pressure", 1}, {"reach", 0.001}};
       },
       "tools[0].suction",
       {"\"suction\" applies only to a suction tool"}},
  });
}

// --- scalpel ---

json& make_scalpel(json& j) {
  json& t = tool0(j);
  t["type"] = "scalpel";
  t["blade"] = {{"length", 0.02}, {"edge", {1, 0, 0.5}}};
  t["cut_force_threshold"] = 0.5;
  return t;
}

TEST(SceneTools, AScalpelsBladeIsRead) {
  json j = with_tools();
  make_scalpel(j)["blade"]["reach"] = 0.001;
  tool0(j)["blade"]["stiffness"] = 2e6;
  const Scene s = parse_scene(j.dump(), kFile);
  const ToolDesc& t = s.tools[0];
  EXPECT_EQ(t.type, ToolDesc::Type::Scalpel);
  EXPECT_TRUE(t.blade.cuts());
  EXPECT_DOUBLE_EQ(t.blade.length, 0.02);
  EXPECT_DOUBLE_EQ(t.blade.threshold, 0.5);
  EXPECT_DOUBLE_EQ(t.blade.reach, 0.001);
  EXPECT_DOUBLE_EQ(t.blade.stiffness, 2e6);
  // The edge is made perpendicular to the first key's axis (z) and unit.
  EXPECT_NEAR((t.blade.edge - Vec3(1, 0, 0)).norm(), 0, 1e-15);
  EXPECT_NEAR((t.blade.reference_axis - Vec3(0, 0, 1)).norm(), 0, 1e-15);
  EXPECT_FALSE(s.tools[1].blade.cuts());  // a probe has no blade
}

TEST(SceneToolsErrors, BadScalpelInput) {
  expect_errors({
      {[](json& j) { make_scalpel(j).erase("blade"); },
       "tools[0].blade",
       {"missing required key \"blade\""}},
      {[](json& j) { make_scalpel(j)["blade"]["length"] = 0; }, "tools[0].blade.length", {"0"}},
      {[](json& j) {
         make_scalpel(j)["blade"]["edge"] = {0, 0, 3};
       },
       "tools[0].blade.edge",
       {"edge along the tool's axis", "not parallel to the axis of path[0]"}},
      {[](json& j) {
         make_scalpel(j)["blade"]["edge"] = {0, 0, 0};
       },
       "tools[0].blade.edge",
       {"zero edge"}},
      {[](json& j) { make_scalpel(j)["cut_force_threshold"] = -1; },
       "tools[0].cut_force_threshold",
       {"-1"}},
      {[](json& j) { make_scalpel(j)["blade"]["stiffness"] = -1; },
       "tools[0].blade.stiffness",
       {"-1"}},
      {[](json& j) { make_scalpel(j)["blade"]["sharpness"] = 1; },
       "tools[0].blade.sharpness",
       {"unknown key"}},
      {[](json& j) {
         tool0(j)["blade"] = {{"length", 0.02}, {"edge", {1, 0, 0}}};
       },
       "tools[0].blade",
       {"\"blade\" applies only to a scalpel"}},
      {[](json& j) { tool0(j)["cut_force_threshold"] = 1; },
       "tools[0].cut_force_threshold",
       {"\"cut_force_threshold\" applies only to a scalpel"}},
  });
}

TEST(SceneToolsErrors, UnknownType) {
  const std::string msg = tools_error([](json& j) { tool0(j)["type"] = "probbe"; });
  expect_error(msg, "tools[0].type",
               {"unknown value \"probbe\"", "did you mean \"probe\"?", "allowed probe"});
  EXPECT_EQ(msg.find("not available yet"), std::string::npos) << msg;
}

// --- shape ---

TEST(SceneToolsErrors, ShapeRequired) {
  const std::string msg = tools_error([](json& j) { tool0(j).erase("shape"); });
  expect_error(msg, "tools[0].shape",
               {"missing required key \"shape\"", "\"sphere\" | \"capsule\""});
}

TEST(SceneToolsErrors, ShapeTypeUnknown) {
  const std::string msg = tools_error([](json& j) { tool0(j)["shape"]["type"] = "box"; });
  expect_error(msg, "tools[0].shape.type", {"unknown value \"box\"", "allowed sphere, capsule"});
}

TEST(SceneToolsErrors, SphereHasNoLength) {
  const std::string msg = tools_error([](json& j) { j["tools"][1]["shape"]["length"] = 0.01; });
  expect_error(msg, "tools[1].shape.length",
               {"unknown key \"length\"", "allowed keys in tools[1].shape: type, radius"});
}

TEST(SceneToolsErrors, UnknownShapeKey) {
  const std::string msg = tools_error([](json& j) { tool0(j)["shape"]["center"] = {0, 0, 0}; });
  expect_error(msg, "tools[0].shape.center",
               {"unknown key \"center\"", "allowed keys in tools[0].shape: type, radius, length"});
}

TEST(SceneToolsErrors, RadiusZero) {
  const std::string msg = tools_error([](json& j) { tool0(j)["shape"]["radius"] = 0; });
  expect_error(msg, "tools[0].shape.radius", {"0 is out of range", "allowed radius > 0 (m)"});
}

TEST(SceneToolsErrors, SphereRadiusRequired) {
  const std::string msg = tools_error([](json& j) { j["tools"][1]["shape"].erase("radius"); });
  expect_error(msg, "tools[1].shape.radius", {"missing required key \"radius\"", "radius > 0"});
}

TEST(SceneToolsErrors, CapsuleLengthNegative) {
  const std::string msg = tools_error([](json& j) { tool0(j)["shape"]["length"] = -0.01; });
  expect_error(msg, "tools[0].shape.length", {"-0.01 is out of range", "allowed length > 0 (m)"});
}

TEST(SceneToolsErrors, CapsuleLengthRequired) {
  const std::string msg = tools_error([](json& j) { tool0(j)["shape"].erase("length"); });
  expect_error(msg, "tools[0].shape.length", {"missing required key \"length\"", "length > 0"});
}

// --- path ---

TEST(SceneToolsErrors, PathRequired) {
  const std::string msg = tools_error([](json& j) { tool0(j).erase("path"); });
  expect_error(msg, "tools[0].path", {"missing required key \"path\"", "one or more path keys"});
}

TEST(SceneToolsErrors, PathEmpty) {
  const std::string msg = tools_error([](json& j) { tool0(j)["path"] = json::array(); });
  expect_error(msg, "tools[0].path", {"empty array", "allowed an array of one or more path keys"});
}

TEST(SceneToolsErrors, PathNotAnArray) {
  const std::string msg = tools_error([](json& j) { tool0(j)["path"] = {{"t", 0}}; });
  expect_error(msg, "tools[0].path",
               {"expected an array of one or more path keys", "got an object"});
}

TEST(SceneToolsErrors, UnknownPathKeyKey) {
  const std::string msg = tools_error([](json& j) { tool0(j)["path"][1]["time"] = 1; });
  expect_error(msg, "tools[0].path[1].time",
               {"unknown key \"time\"", "allowed keys in tools[0].path[1]: t, position, axis"});
}

TEST(SceneToolsErrors, KeyTimeRequired) {
  const std::string msg = tools_error([](json& j) { tool0(j)["path"][1].erase("t"); });
  expect_error(msg, "tools[0].path[1].t", {"missing required key \"t\"", "t >= 0 (s)"});
}

TEST(SceneToolsErrors, KeyTimeNegative) {
  const std::string msg = tools_error([](json& j) { tool0(j)["path"][0]["t"] = -0.1; });
  expect_error(msg, "tools[0].path[0].t", {"-0.1 is out of range", "allowed t >= 0 (s)"});
}

TEST(SceneToolsErrors, KeyTimeNotANumber) {
  const std::string msg = tools_error([](json& j) { tool0(j)["path"][0]["t"] = "0"; });
  expect_error(msg, "tools[0].path[0].t", {"expected a number", "allowed t >= 0 (s)"});
}

TEST(SceneToolsErrors, KeyTimesMustIncreaseStrictly) {
  const std::string msg = tools_error([](json& j) { tool0(j)["path"][1]["t"] = 0.0; });
  expect_error(msg, "tools[0].path[1].t",
               {"t = 0 is not greater than t = 0 of path[0]", "strictly increasing"});
}

TEST(SceneToolsErrors, KeyTimesGoingBackNameBothValues) {
  const std::string msg = tools_error([](json& j) {
    tool0(j)["path"].push_back({{"t", 0.25}, {"position", {0, 0, 0.04}}});
  });
  expect_error(msg, "tools[0].path[2].t",
               {"t = 0.25 is not greater than t = 0.5 of path[1]", "strictly increasing"});
}

TEST(SceneToolsErrors, KeyPositionRequired) {
  const std::string msg = tools_error([](json& j) { tool0(j)["path"][1].erase("position"); });
  expect_error(msg, "tools[0].path[1].position", {"missing required key \"position\"", "(m)"});
}

TEST(SceneToolsErrors, KeyPositionWrongLength) {
  const std::string msg = tools_error([](json& j) { tool0(j)["path"][1]["position"] = {0, 0}; });
  expect_error(msg, "tools[0].path[1].position",
               {"expected an array of 3 numbers", "got an array of 2 elements", "(m)"});
}

TEST(SceneToolsErrors, KeyPositionComponentNotANumber) {
  const std::string msg = tools_error([](json& j) {
    tool0(j)["path"][0]["position"] = {0, "y", 0};
  });
  expect_error(msg, "tools[0].path[0].position[1]", {"expected a number", "got string \"y\""});
}

TEST(SceneToolsErrors, KeyAxisZero) {
  const std::string msg = tools_error([](json& j) { tool0(j)["path"][1]["axis"] = {0, 0, 0}; });
  expect_error(msg, "tools[0].path[1].axis", {"zero axis", "allowed a non-zero direction"});
}

TEST(SceneToolsErrors, KeyAxisWrongType) {
  const std::string msg = tools_error([](json& j) { tool0(j)["path"][0]["axis"] = "z"; });
  expect_error(msg, "tools[0].path[0].axis", {"expected an array of 3 numbers", "string \"z\""});
}

// --- friction, control, coupling ---

TEST(SceneToolsErrors, FrictionNegative) {
  const std::string msg = tools_error([](json& j) { tool0(j)["friction"] = -0.1; });
  expect_error(msg, "tools[0].friction", {"-0.1 is out of range", "allowed 0 <= friction <= 10"});
}

TEST(SceneToolsErrors, FrictionAbsurd) {
  const std::string msg = tools_error([](json& j) { tool0(j)["friction"] = 20; });
  expect_error(msg, "tools[0].friction", {"20 is out of range", "allowed 0 <= friction <= 10"});
}

TEST(SceneToolsErrors, ControlUnknown) {
  const std::string msg = tools_error([](json& j) { tool0(j)["control"] = "hapitc"; });
  expect_error(msg, "tools[0].control",
               {"unknown value \"hapitc\"", "did you mean \"haptic\"?", "allowed path, haptic"});
}

TEST(SceneToolsErrors, CouplingOnlyForHapticControl) {
  const std::string msg = tools_error([](json& j) { j["tools"][1]["control"] = "path"; });
  expect_error(msg, "tools[1].coupling",
               {"\"coupling\" applies only to a haptic tool", "\"control\": \"haptic\""});
}

TEST(SceneToolsErrors, CouplingWithDefaultControlIsRejected) {
  const std::string msg = tools_error([](json& j) { j["tools"][1].erase("control"); });
  expect_error(msg, "tools[1].coupling", {"applies only to a haptic tool", "remove it"});
}

TEST(SceneToolsErrors, UnknownCouplingKey) {
  const std::string msg = tools_error([](json& j) { j["tools"][1]["coupling"]["spring"] = 1; });
  expect_error(msg, "tools[1].coupling.spring",
               {"unknown key \"spring\"",
                "allowed keys in tools[1].coupling: stiffness, damping, mass, max_force, "
                "max_speed"});
}

TEST(SceneToolsErrors, CouplingRanges) {
  struct Case {
    const char* key;
    double value;
    const char* allowed;
  };
  for (const Case& c : {Case{"stiffness", 0, "allowed stiffness > 0 (N/m)"},
                        Case{"damping", -1, "allowed damping >= 0 (N s/m)"},
                        Case{"mass", 0, "allowed mass > 0 (kg)"},
                        Case{"max_force", -2, "allowed max_force > 0 (N)"},
                        Case{"max_speed", 0, "allowed max_speed > 0 (m/s)"}}) {
    const std::string msg =
        tools_error([&](json& j) { j["tools"][1]["coupling"][c.key] = c.value; });
    expect_error(msg, std::string("tools[1].coupling.") + c.key, {"is out of range", c.allowed});
  }
}

}  // namespace
}  // namespace phyxel
