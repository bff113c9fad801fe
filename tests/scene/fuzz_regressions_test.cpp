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
#include <functional>
#include <span>
#include <sstream>
#include <stdexcept>
#include <string>
#include <typeinfo>
#include <vector>

#include "engine/geometry/mesh.h"
#include "engine/run/checkpoint.h"
#include "engine/scene/scene.h"
#include "engine/surgery/haptic_protocol.h"

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

// What reading `file` gave: the mesh's vertices and triangles, or the error.
std::string obj_outcome(const std::function<TriangleMesh()>& read) {
  try {
    const TriangleMesh mesh = read();
    (void)mesh.contains(mesh.bounds.center());
    std::ostringstream out;
    for (const Vec3& v : mesh.vertices) out << v.transpose() << ";";
    for (const Eigen::Vector3i& t : mesh.triangles) out << t.transpose() << ";";
    return out.str();
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    return std::string("error: ") + e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not a std::runtime_error (" << type_of(e) << "): " << e.what();
    return "";
  }
}

// Read from the file (load_obj_mesh) and, as fuzz/fuzz_obj.cpp reads them, from memory
// (parse_obj_mesh, which leaves no temporary file behind): the same mesh or the same error.
TEST(FuzzRegressions, ObjFilesAreReadOrRejectedWithRuntimeError) {
  const std::vector<fs::path> files = inputs("fuzz_obj");
  ASSERT_FALSE(files.empty());
  for (const fs::path& file : files) {
    SCOPED_TRACE(file.filename().string());
    const std::string from_file = obj_outcome([&] { return load_obj_mesh(file, 1.0); });
    const std::string from_memory =
        obj_outcome([&] { return parse_obj_mesh(read_bytes(file), file, 1.0); });
    EXPECT_EQ(from_memory, from_file);
  }
}

TEST(FuzzRegressions, CheckpointsAreReadOrRejectedWithCheckpointError) {
  const std::vector<fs::path> files = inputs("fuzz_checkpoint");
  ASSERT_FALSE(files.empty());
  for (const fs::path& file : files) {
    SCOPED_TRACE(file.filename().string());
    try {
      const Checkpoint c = parse_checkpoint(read_bytes(file), file.string());
      EXPECT_EQ(c.velocity.size(), c.displacement.size());
    } catch (const CheckpointError& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).rfind(file.string() + ": ", 0), 0u) << e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not a CheckpointError (" << type_of(e) << "): " << e.what();
    }
  }
}

// As fuzz/fuzz_haptic.cpp checks: a datagram that decodes holds finite values and encodes
// back to its own bytes.
TEST(FuzzRegressions, HapticDatagramsDecodeExactlyOrAreRefused) {
  const std::vector<fs::path> files = inputs("fuzz_haptic");
  ASSERT_FALSE(files.empty());
  int decoded = 0;
  for (const fs::path& file : files) {
    SCOPED_TRACE(file.filename().string());
    const std::string bytes = read_bytes(file);
    const std::span data(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
    haptic::PoseMessage pose;
    if (haptic::decode(data, pose) == haptic::DecodeStatus::Ok) {
      ++decoded;
      EXPECT_TRUE(pose.position.allFinite() && pose.axis.allFinite());
      const auto again = haptic::encode(pose);
      EXPECT_EQ(std::string(again.begin(), again.end()), bytes);
    }
    haptic::ForceMessage force;
    if (haptic::decode(data, force) == haptic::DecodeStatus::Ok) {
      ++decoded;
      EXPECT_TRUE(force.force.allFinite());
      const auto again = haptic::encode(force);
      EXPECT_EQ(std::string(again.begin(), again.end()), bytes);
    }
  }
  EXPECT_EQ(decoded, 2);  // pose.bin and force.bin
}

}  // namespace
}  // namespace phyxel
