// libFuzzer target: the scene reader on arbitrary bytes (scripts/fuzz.sh, docs/decisions.md).
// parse_scene's contract is that every problem with the input is a SceneError; any other
// exception escapes and libFuzzer reports it, as it reports crashes and sanitizer errors.
// The scene "lives" in tests/data/scenes so that mesh paths resolve to the test meshes.
#include <cstddef>
#include <cstdint>
#include <string>

#include "engine/scene/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    phyxel::parse_scene(text, PHYXEL_SOURCE_DIR "/tests/data/scenes/fuzz.json");
  } catch (const phyxel::SceneError&) {
  }
  return 0;
}
