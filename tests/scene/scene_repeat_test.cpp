// A tool's "repeat" and "repeat_shift" (docs/scene-format.md, tools[i]): the cycle read, its
// refusals, and the ToolTrack's motions wrapping with it (the path, and the grasp window closing
// again), each cycle moved by the shift.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "engine/scene/scene.h"
#include "engine/surgery/tool_track.h"
#include "tests/scene/scene_error_helpers.h"

namespace phyxel {
namespace {

using nlohmann::json;
using namespace scene_test;

// A grasper that goes down and back in 0.2 s, jaws closed in [0.05, 0.1), every 0.25 s.
json with_cycle() {
  json j = demo();
  j["tools"] = json::parse(R"([
    {"name": "jaws", "type": "grasper", "shape": {"type": "sphere", "radius": 0.001},
     "grasp": {"reach": 0.002, "from": 0.05, "until": 0.1}, "repeat": 0.25,
     "path": [{"t": 0, "position": [0, 0, 0.05]}, {"t": 0.1, "position": [0, 0, 0.04]},
              {"t": 0.2, "position": [0, 0, 0.05]}]}])");
  return j;
}

TEST(SceneRepeat, TheToolsCycleRepeatsItsPathAndItsGrasp) {
  const Scene s = parse_scene(with_cycle().dump(), kFile);
  ASSERT_EQ(s.tools.size(), 1u);
  EXPECT_DOUBLE_EQ(s.tools[0].repeat, 0.25);
  ToolTrack track(s.tools, {});
  const double dt = 0.01;
  const std::vector<ToolMotion> m = track.motions(0, 60, dt);  // 0.6 s: two cycles and more
  ASSERT_EQ(m.size(), 60u);
  for (int k = 0; k < 35; ++k) {  // substep k + 25 does what substep k did
    SCOPED_TRACE(k);
    EXPECT_NEAR((m[k + 25].to.position - m[k].to.position).norm(), 0, 1e-12);
    EXPECT_EQ(m[k + 25].grip_closed, m[k].grip_closed);
  }
  EXPECT_TRUE(m[30].grip_closed);                   // 0.305 s: 0.055 s into the second cycle
  EXPECT_FALSE(m[40].grip_closed);                  // 0.405 s: 0.155 s into it
  EXPECT_NEAR(m[34].to.position.z(), 0.04, 1e-12);  // 0.35 s: the bottom again
}

TEST(SceneRepeat, EachCycleIsShiftedByTheRepeatShift) {
  json j = with_cycle();
  j["tools"][0]["repeat_shift"] = {0.001, -0.002, 0};
  const Scene s = parse_scene(j.dump(), kFile);
  ASSERT_EQ(s.tools.size(), 1u);
  EXPECT_EQ(s.tools[0].repeat_shift, Vec3(0.001, -0.002, 0));
  const Vec3 shift = s.tools[0].repeat_shift;
  ToolTrack track(s.tools, {});
  const double dt = 0.01;
  const std::vector<ToolMotion> m = track.motions(0, 60, dt);
  for (int k = 0; k < 35; ++k) {  // substep k + 25 does what substep k did, one shift over
    SCOPED_TRACE(k);
    EXPECT_NEAR((m[k + 25].to.position - m[k].to.position - shift).norm(), 0, 1e-12);
    EXPECT_EQ(m[k + 25].grip_closed, m[k].grip_closed);
  }
  EXPECT_NEAR((m[59].to.position - Vec3(0.002, -0.004, 0.04)).norm(), 0, 1e-12);  // 0.6 s
  // A chunk that starts where an earlier one ended (a resumed run) continues the same poses,
  // and the broad phase's bounds hold the shifted tool.
  ToolTrack later(s.tools, {});
  later.restore({m[29].to}, {track.stats()[0]});
  const std::vector<ToolMotion> rest = later.motions(30, 30, dt);
  for (int k = 0; k < 30; ++k) EXPECT_EQ(rest[k].to.position, m[k + 30].to.position);
  const Bounds b = later.swept_bounds(0.3, 0.6);
  for (int k = 0; k < 30; ++k) {
    const Vec3& x = rest[k].to.position;
    EXPECT_TRUE((x.array() >= b.min.array()).all() && (x.array() <= b.max.array()).all()) << k;
  }
}

TEST(SceneRepeat, BadCyclesAreRefused) {
  const auto error = [](const std::function<void(json&)>& edit) {
    json j = with_cycle();
    edit(j);
    return error_text(j.dump());
  };
  expect_error(error([](json& j) { j["tools"][0]["repeat"] = 0.15; }), "tools[0].repeat",
               {"shorter than the path"});
  expect_error(error([](json& j) {
                 j["tools"][0]["path"][2]["position"] = {0, 0, 0.045};
               }),
               "tools[0].repeat", {"must end where it begins"});
  expect_error(error([](json& j) { j["tools"][0]["repeat"] = -1; }), "tools[0].repeat", {"repeat"});
  expect_error(error([](json& j) { j["tools"][0]["control"] = "haptic"; }), "tools[0].repeat",
               {"only to a path tool"});
  expect_error(error([](json& j) {
                 j["tools"][0].erase("repeat");
                 j["tools"][0]["repeat_shift"] = {0, 0.001, 0};
               }),
               "tools[0].repeat_shift", {"only to a repeating path", "add \"repeat\""});
  expect_error(error([](json& j) {
                 j["tools"][0]["repeat_shift"] = {0, 2, 0};
               }),
               "tools[0].repeat_shift[1]", {"-1 <= repeat_shift[1] <= 1 (m)"});
  expect_error(error([](json& j) { j["tools"][0]["repeat_shift"] = 0.001; }),
               "tools[0].repeat_shift", {"[x, y, z]"});
}

}  // namespace
}  // namespace phyxel
