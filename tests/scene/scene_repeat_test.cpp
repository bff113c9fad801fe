// A tool's "repeat" (docs/scene-format.md, tools[i]): the cycle read, its refusals, and the
// ToolTrack's motions wrapping with it (the path, and the grasp window closing again).
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
}

}  // namespace
}  // namespace phyxel
