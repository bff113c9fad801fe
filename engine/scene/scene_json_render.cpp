// Scene files: the `camera` and `render` keys (docs/scene-format.md, "Rendering"). Called by
// parse_scene (scene_json.cpp) with the document's root.
#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "engine/scene/file_kind.h"
#include "engine/scene/json_reader.h"
#include "engine/scene/scene.h"
#include "engine/scene/scene_json_tools.h"

namespace phyxel {
namespace {

namespace fs = std::filesystem;
using json_reader::Limits;
using json_reader::Node;

// Largest image side we agree to render (a side-by-side frame is twice as wide); the device
// limit (maxImageDimension2D) is checked again when the renderer starts.
constexpr int kMaxImageSide = 8192;

bool read_bool(const Node& node) {
  if (!node.value().is_boolean()) {
    node.fail("expected true or false, got " + node.value().dump(), "allowed true or false");
  }
  return node.value().get<bool>();
}

CameraSettings read_camera(const Node& node) {
  node.expect_object(
      "a camera object {\"position\": [x, y, z], \"target\": [x, y, z], \"up\": [x, y, z], "
      "\"fov_y_deg\": deg, \"near\": m, \"far\": m}",
      {"position", "target", "up", "fov_y_deg", "near", "far"});
  CameraSettings c;
  if (const auto p = node.find("position")) c.position = p->vec3(Limits::any(), "m");
  if (const auto t = node.find("target")) c.target = t->vec3(Limits::any(), "m");
  c.up = node.vec3_or("up", c.up, Limits::any(), "");
  if (c.up.norm() == 0) {
    node.at("up", "").fail("the up vector is zero", "allowed a non-zero direction [x, y, z]");
  }
  c.fov_y_deg = node.number_or("fov_y_deg", c.fov_y_deg, Limits::open(0, 180), "degrees");
  c.near = node.number_or("near", c.near, Limits::above(0), "m");
  c.far = node.number_or("far", c.far, Limits::above(0), "m");
  if (c.near >= c.far) {
    const auto far = node.find("far");
    const Node at = far ? *far : node.at("near", "");
    at.fail("near = " + json_reader::format_number(c.near) +
                " is not less than far = " + json_reader::format_number(c.far),
            "allowed 0 < near < far (m)");
  }
  if (c.position && c.target) {
    const Vec3 view = *c.target - *c.position;
    if (view.norm() == 0) {
      node.at("target", "")
          .fail("the target is the camera position", "allowed a target away from the position");
    }
    if (view.normalized().cross(c.up.normalized()).norm() < 1e-6) {
      const auto up = node.find("up");
      (up ? *up : node.at("target", ""))
          .fail("the up vector is parallel to the viewing direction",
                "allowed an up direction not parallel to target - position");
    }
  }
  return c;
}

StereoSettings read_stereo(const Node& node) {
  node.expect_object(
      "a stereo object {\"ipd\": m, \"focal_distance\": m, \"layout\": \"side-by-side\" | "
      "\"anaglyph\", \"swap_eyes\": false}",
      {"ipd", "focal_distance", "layout", "swap_eyes"});
  StereoSettings s;
  s.ipd = node.number_or("ipd", s.ipd, Limits::at_least(0), "m");
  if (const auto f = node.find("focal_distance"))
    s.focal_distance = f->number(Limits::above(0), "m");
  if (const auto layout = node.find("layout")) {
    s.layout = layout->choice({"side-by-side", "anaglyph"}) == "anaglyph"
                   ? StereoSettings::Layout::Anaglyph
                   : StereoSettings::Layout::SideBySide;
  }
  if (const auto swap = node.find("swap_eyes")) s.swap_eyes = read_bool(*swap);
  return s;
}

// An existing image file named by `node` (a string), relative to the scene's folder; `noun`
// names it in the message (default: the key).
fs::path read_image_path(const Node& node, const fs::path& folder, const std::string& what,
                         const std::string& noun = {}) {
  const fs::path path = folder / node.text();
  std::string allowed = "allowed " + what + ", relative to the scene file's folder (";
  allowed += folder.empty() ? std::string("the working directory") : folder.string();
  allowed += ")";
  if (const std::string why = not_a_regular_file(path); !why.empty())
    node.fail((noun.empty() ? node.leaf() : noun) + " file \"" + path.string() + "\" " + why,
              allowed);
  return path;
}

// `render.environment`: "image.png", or {"image": "image.png", "area_ratio": K}.
void read_environment(const Node& node, const fs::path& folder, RenderSettings& r) {
  const std::string what = "a square PNG or JPEG image";
  if (node.value().is_string()) {
    r.environment = read_image_path(node, folder, what);
    return;
  }
  node.expect_object(
      "an image file name, or an environment object {\"image\": \"field.png\", "
      "\"area_ratio\": K}",
      {"image", "area_ratio"});
  r.environment = read_image_path(node.at("image", "an image file name"), folder, what);
  r.environment_area_ratio =
      node.number_or("area_ratio", r.environment_area_ratio, Limits::above(0), "");
}

// `render.video_texture`: "clip.mp4", or {"file": "clip.mp4", "loop_blend": B,
// "repair_specular": true}. Whether the file decodes is checked when the renderer opens it
// (render/video_texture.h), before the run starts.
void read_video_texture(const Node& node, const fs::path& folder, RenderSettings& r) {
  const std::string what = "a video file that FFmpeg decodes (MP4, MKV, WebM, AVI, ...)";
  if (node.value().is_string()) {
    r.video_texture.file = read_image_path(node, folder, what, "video");
    return;
  }
  node.expect_object(
      "a video file name, or a video texture object {\"file\": \"clip.mp4\", \"loop_blend\": "
      "frames, \"repair_specular\": true}",
      {"file", "loop_blend", "repair_specular"});
  r.video_texture.file =
      read_image_path(node.at("file", "a video file name"), folder, what, "video");
  r.video_texture.loop_blend =
      static_cast<int>(node.integer_or("loop_blend", 0, Limits{0, 1000, true, true}));
  if (const auto repair = node.find("repair_specular")) {
    r.video_texture.repair_specular = read_bool(*repair);
  }
}

RenderSettings read_render(const Node& node, const fs::path& folder) {
  node.expect_object(
      "a render object {\"mode\": \"none\" | \"mono\" | \"stereo\", \"width\": px, \"height\": "
      "px, \"every\": n, \"texture\": \"image.png\", \"video_texture\": \"clip.mp4\", "
      "\"environment\": \"image.png\", \"video\": \"out.mp4\", \"stereo\": {...}, "
      "\"backdrop\": [...], \"instruments\": [...]}",
      {"mode", "width", "height", "every", "texture", "video_texture", "environment", "video",
       "stereo", "backdrop", "instruments"});
  RenderSettings r;
  if (const auto mode = node.find("mode")) {
    const std::string m = mode->choice({"none", "mono", "stereo"});
    r.mode = m == "mono"     ? RenderSettings::Mode::Mono
             : m == "stereo" ? RenderSettings::Mode::Stereo
                             : RenderSettings::Mode::None;
  }
  const Limits side{1, kMaxImageSide, true, true};
  r.width = static_cast<int>(node.integer_or("width", r.width, side));
  r.height = static_cast<int>(node.integer_or("height", r.height, side));
  r.every = node.integer_or("every", r.every, Limits::at_least(1));
  if (const auto texture = node.find("texture")) {
    r.texture = read_image_path(*texture, folder, "a PNG or JPEG image");
  }
  if (const auto video = node.find("video_texture")) read_video_texture(*video, folder, r);
  if (const auto environment = node.find("environment")) {
    read_environment(*environment, folder, r);
  }
  // Relative to the run's output folder (phyxel run --out), where the frames go.
  if (const auto video = node.find("video")) r.video = video->text();
  if (const auto stereo = node.find("stereo")) r.stereo = read_stereo(*stereo);
  if (const auto backdrop = node.find("backdrop")) r.backdrop = read_backdrop(*backdrop, folder);
  if (const auto instruments = node.find("instruments"))
    r.instruments = read_instruments(*instruments);
  return r;
}

}  // namespace

// The `camera` and `render` members of the root object, when present.
void read_view_settings(const Node& root, Scene& scene) {
  if (const auto camera = root.find("camera")) scene.camera = read_camera(*camera);
  if (const auto render = root.find("render")) {
    scene.render = read_render(*render, scene.file.parent_path());
  }
}

}  // namespace phyxel
