// The scene file's `camera` and `render` keys: defaults, values, and one-line errors that name
// the file and the key.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "engine/scene/scene.h"
#include "tests/render/render_test_util.h"
#include "tests/support/support.h"

namespace phyxel {
namespace {

std::string scene_json(const std::string& extra) {
  return R"({"simulation": {"dt": 1e-4, "steps": 10},
    "objects": [{"name": "b", "shape": {"type": "box", "min": [0, 0, 0], "max": [0.01, 0.01, 0.01]},
                 "spacing": 0.005, "material": {"young": 1000, "poisson": 0.3, "density": 1000}}])" +
         (extra.empty() ? std::string() : ", " + extra) + "}";
}

std::string error_of(const std::string& extra, const std::filesystem::path& file = "s.json") {
  return test::error_of<SceneError>([&] { parse_scene(scene_json(extra), file); });
}

TEST(RenderScene, DefaultsWhenAbsent) {
  const Scene s = parse_scene(scene_json(""), "s.json");
  EXPECT_EQ(s.render.mode, RenderSettings::Mode::None);
  EXPECT_EQ(s.render.width, 1280);
  EXPECT_EQ(s.render.height, 720);
  EXPECT_EQ(s.render.every, 10);
  EXPECT_TRUE(s.render.texture.empty());
  EXPECT_FALSE(s.camera.position.has_value());
  EXPECT_FALSE(s.camera.target.has_value());
  EXPECT_EQ(s.camera.fov_y_deg, 45);
  EXPECT_EQ(s.camera.near, 0.01);
  EXPECT_EQ(s.camera.far, 10);
  EXPECT_EQ(s.render.stereo.ipd, 0.064);
  EXPECT_FALSE(s.render.stereo.focal_distance.has_value());
  EXPECT_EQ(s.render.stereo.layout, StereoSettings::Layout::SideBySide);
  EXPECT_FALSE(s.render.stereo.swap_eyes);
}

TEST(RenderScene, ReadsEveryKey) {
  const std::filesystem::path dir = render::test::test_out_dir() / "render_scene";
  std::filesystem::create_directories(dir);
  render::write_png(dir / "tex.png", render::RgbaImage(2, 2));
  const Scene s =
      parse_scene(scene_json(R"("camera": {"position": [0, -0.3, 0.2], "target": [0, 0, 0.01],
                               "up": [0, 0, 1], "fov_y_deg": 30, "near": 0.02, "far": 3},
                    "render": {"mode": "stereo", "width": 640, "height": 480, "every": 5,
                               "texture": "tex.png",
                               "stereo": {"ipd": 0.05, "focal_distance": 0.4,
                                          "layout": "anaglyph", "swap_eyes": true}})"),
                  dir / "s.json");
  EXPECT_TRUE(s.camera.position->isApprox(Vec3(0, -0.3, 0.2)));
  EXPECT_TRUE(s.camera.target->isApprox(Vec3(0, 0, 0.01)));
  EXPECT_EQ(s.camera.fov_y_deg, 30);
  EXPECT_EQ(s.camera.near, 0.02);
  EXPECT_EQ(s.camera.far, 3);
  EXPECT_EQ(s.render.mode, RenderSettings::Mode::Stereo);
  EXPECT_EQ(s.render.width, 640);
  EXPECT_EQ(s.render.height, 480);
  EXPECT_EQ(s.render.every, 5);
  EXPECT_EQ(s.render.texture, dir / "tex.png");  // relative to the scene's folder
  EXPECT_EQ(s.render.stereo.ipd, 0.05);
  EXPECT_EQ(*s.render.stereo.focal_distance, 0.4);
  EXPECT_EQ(s.render.stereo.layout, StereoSettings::Layout::Anaglyph);
  EXPECT_TRUE(s.render.stereo.swap_eyes);
}

TEST(RenderScene, BadValuesNameTheFileAndKey) {
  const struct {
    const char* json;
    const char* key;
    const char* problem;
  } cases[] = {
      {R"("camera": {"near": 1, "far": 0.5})", "s.json: camera.far:", "not less than far"},
      {R"("camera": {"near": 20})", "s.json: camera.near:", "not less than far"},
      {R"("camera": {"near": 0})", "s.json: camera.near:", "near"},
      {R"("camera": {"fov_y_deg": 180})", "s.json: camera.fov_y_deg:", "fov_y_deg"},
      {R"("camera": {"position": [0, 0, 1], "target": [0, 0, 1]})",
       "s.json: camera.target:", "target is the camera position"},
      {R"("camera": {"position": [0, 0, 1], "target": [0, 0, 0]})",
       "s.json: camera.target:", "parallel"},
      {R"("camera": {"up": [0, 0, 0]})", "s.json: camera.up:", "zero"},
      {R"("render": {"stereo": {"ipd": -0.01}})", "s.json: render.stereo.ipd:", "ipd >= 0"},
      {R"("render": {"stereo": {"focal_distance": 0}})",
       "s.json: render.stereo.focal_distance:", "focal_distance > 0"},
      {R"("render": {"stereo": {"layout": "top-bottom"}})",
       "s.json: render.stereo.layout:", "side-by-side"},
      {R"("render": {"stereo": {"swap_eyes": 1}})",
       "s.json: render.stereo.swap_eyes:", "true or false"},
      {R"("render": {"width": 0})", "s.json: render.width:", "8192"},
      {R"("render": {"height": -5})", "s.json: render.height:", "8192"},
      {R"("render": {"width": 100000})", "s.json: render.width:", "8192"},
      {R"("render": {"every": 0})", "s.json: render.every:", "every >= 1"},
      {R"("render": {"mode": "mon"})", "s.json: render.mode:", "mono"},
      {R"("render": {"texture": "nowhere.png"})", "s.json: render.texture:", "does not exist"},
      {R"("render": {"colour": 1})", "s.json: render.colour:", "unknown key"},
  };
  for (const auto& c : cases) {
    const std::string m = error_of(c.json);
    EXPECT_EQ(m.rfind(c.key, 0), 0u) << c.json << "\n  -> " << m;
    EXPECT_NE(m.find(c.problem), std::string::npos) << c.json << "\n  -> " << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
}

}  // namespace
}  // namespace phyxel
