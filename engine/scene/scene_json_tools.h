// Private to the scene reader (scene_json*.cpp): the `tools` key, read by scene_json_tools.cpp
// and called by parse_scene (scene_json.cpp) with the document's root, and the readers that
// the files share.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <string_view>
#include <utility>
#include <vector>

#include "engine/scene/json_reader.h"
#include "engine/scene/scene.h"

namespace phyxel {

// The root's `tools` array, when present, into scene.tools (docs/scene-format.md, "tools").
// Throws SceneError "FILE: JSON.PATH: problem; allowed ..." at the first invalid value.
void read_tools(const json_reader::Node& root, Scene& scene);

inline constexpr std::string_view kShapeExpected =
    "a shape object {\"type\": \"box\" | \"sphere\" | \"ellipsoid\" | \"mesh\" | \"image\", "
    "...}";

struct ImageVolume;
// The images read while one scene is read, by file and frame: shapes that name the same file
// read it once.
using ImageReads =
    std::map<std::pair<std::filesystem::path, int64_t>, std::shared_ptr<const ImageVolume>>;

// A shape object of the scene format (scene_json.cpp); a mesh or an image is loaded relative to
// `folder`, an image through `images` when given.
Shape read_shape(const json_reader::Node& node, const std::filesystem::path& folder,
                 ImageReads* images = nullptr);
// An image shape {"type": "image", "file": ..., "labels": [...] | "threshold": x, "frame": n}
// (scene_json_image.cpp).
Shape read_image_shape(const json_reader::Node& node, const std::filesystem::path& folder,
                       ImageReads* images);
// A tool's shape object {"type": "sphere" | "capsule", "radius": m, "length": m}
// (scene_json_tools.cpp).
ToolShape read_tool_shape(const json_reader::Node& node);

// `render.backdrop` and `render.instruments` (scene_json_backdrop.cpp).
std::vector<BackdropItem> read_backdrop(const json_reader::Node& node,
                                        const std::filesystem::path& folder);
std::vector<InstrumentDrawable> read_instruments(const json_reader::Node& node);

}  // namespace phyxel
