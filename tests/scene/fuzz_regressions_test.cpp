// Replays the inputs in tests/data/fuzz/ (README.md there): findings of fuzzing
// (scripts/fuzz.sh) and hand-made inputs of the kinds readers get wrong. Each must be read
// cleanly or rejected the documented way: SceneError for scenes, std::runtime_error for OBJ
// files, with a one-line message. A crash fails the run; under the sanitizer job of
// scripts/dev.sh so does any memory error or undefined behaviour.
#include <gtest/gtest.h>

#include <algorithm>
#include <exception>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <typeinfo>
#include <vector>

#include "engine/geometry/mesh.h"
#include "engine/scene/scene.h"

namespace phyxel {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> inputs(const std::string& target) {
  std::vector<fs::path> files;
  for (const auto& entry :
       fs::directory_iterator(fs::path(PHYXEL_SOURCE_DIR) / "tests/data/fuzz" / target))
    if (entry.is_regular_file()) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

std::string read_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string type_of(const std::exception& e) {
  return typeid(e).name();
}

TEST(FuzzRegressions, ScenesAreReadOrRejectedWithSceneError) {
  const std::vector<fs::path> files = inputs("fuzz_scene");
  ASSERT_FALSE(files.empty());
  // As in fuzz/fuzz_scene.cpp: mesh paths resolve against tests/data/scenes.
  const fs::path scene_file = fs::path(PHYXEL_SOURCE_DIR) / "tests/data/scenes/fuzz.json";
  for (const fs::path& file : files) {
    SCOPED_TRACE(file.filename().string());
    try {
      parse_scene(read_bytes(file), scene_file);
    } catch (const SceneError& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not a SceneError (" << type_of(e) << "): " << e.what();
    }
  }
}

TEST(FuzzRegressions, ObjFilesAreReadOrRejectedWithRuntimeError) {
  const std::vector<fs::path> files = inputs("fuzz_obj");
  ASSERT_FALSE(files.empty());
  for (const fs::path& file : files) {
    SCOPED_TRACE(file.filename().string());
    try {
      const TriangleMesh mesh = load_obj_mesh(file, 1.0);
      (void)mesh.contains(mesh.bounds.center());
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not a std::runtime_error (" << type_of(e) << "): " << e.what();
    }
  }
}

}  // namespace
}  // namespace phyxel
