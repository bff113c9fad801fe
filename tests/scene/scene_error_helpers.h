// Helpers of the scene error tests: start from the shipped all-keys scene, break one thing,
// and check the one-line SceneError "FILE: JSON.PATH: problem; allowed ...".
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "engine/scene/scene.h"

namespace phyxel::scene_test {

using nlohmann::json;

inline constexpr const char* kFile = "scenes/fake_scene.json";

inline json demo() {
  return json::parse(
      std::ifstream(std::filesystem::path(PHYXEL_SOURCE_DIR) / "scenes/beam_tumour.json"));
}

inline std::string error_text(const std::string& text) {
  try {
    parse_scene(text, kFile);
  } catch (const SceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no SceneError for: " << text;
  return {};
}

inline std::string error_with(const std::function<void(json&)>& edit) {
  json j = demo();
  edit(j);
  return error_text(j.dump());
}

// One line, starting "FILE: PATH: ", with a "; what is allowed" part, containing every part.
inline void expect_error(const std::string& msg, const std::string& path,
                         const std::vector<std::string>& parts) {
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  EXPECT_EQ(msg.rfind(std::string(kFile) + ": " + path + ": ", 0), 0u) << msg;
  EXPECT_NE(msg.find("; "), std::string::npos) << msg;
  for (const std::string& part : parts) {
    EXPECT_NE(msg.find(part), std::string::npos) << "no \"" << part << "\" in: " << msg;
  }
}

inline json& object0(json& j) {
  return j["objects"][0];
}
inline json& material0(json& j) {
  return j["objects"][0]["material"];
}

}  // namespace phyxel::scene_test
