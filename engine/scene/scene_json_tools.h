// Private to the scene reader (scene_json*.cpp): the `tools` key, read by scene_json_tools.cpp
// and called by parse_scene (scene_json.cpp) with the document's root.
#pragma once

#include "engine/scene/json_reader.h"
#include "engine/scene/scene.h"

namespace phyxel {

// The root's `tools` array, when present, into scene.tools (docs/scene-format.md, "tools").
// Throws SceneError "FILE: JSON.PATH: problem; allowed ..." at the first invalid value.
void read_tools(const json_reader::Node& root, Scene& scene);

}  // namespace phyxel
