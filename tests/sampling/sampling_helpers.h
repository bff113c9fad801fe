// Scene builders and fixtures shared by the sampling tests.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "engine/sampling/phyxel_set.h"
#include "engine/scene/scene.h"

namespace phyxel::test {

inline Material tissue(double density = 1000) {
  Material m;
  m.young = 3000;
  m.poisson = 0.45;
  m.density = density;
  return m;
}

inline Shape box(const Vec3& min, const Vec3& max) {
  Shape s;
  s.type = Shape::Type::Box;
  s.min = min;
  s.max = max;
  return s;
}

inline Shape sphere(const Vec3& center, double radius) {
  Shape s;
  s.type = Shape::Type::Sphere;
  s.center = center;
  s.radius = radius;
  return s;
}

inline Shape ellipsoid(const Vec3& center, const Vec3& radii) {
  Shape s;
  s.type = Shape::Type::Ellipsoid;
  s.center = center;
  s.radii = radii;
  return s;
}

inline ObjectDesc object(const std::string& name, const Shape& shape, double spacing) {
  ObjectDesc o;
  o.name = name;
  o.shape = shape;
  o.spacing = spacing;
  o.support_radius = 2 * spacing;
  o.material = tissue();
  return o;
}

inline Scene scene_of(std::vector<ObjectDesc> objects) {
  Scene scene;
  scene.file = "test_scene.json";
  scene.objects = std::move(objects);
  return scene;
}

inline double total_volume(const PhyxelSet& set) {
  double v = 0;
  for (double x : set.volume) v += x;
  return v;
}

// A fresh folder for files a test writes, unique per test so that ctest -j is safe.
inline std::filesystem::path test_dir() {
  const char* env = std::getenv("PHYXEL_TEST_OUT");
  const std::filesystem::path base =
      env ? std::filesystem::path(env) : std::filesystem::temp_directory_path();
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::filesystem::path dir =
      base / "sampling" / (std::string(info->test_suite_name()) + "." + info->name());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline std::filesystem::path write_file(const std::filesystem::path& path,
                                        const std::string& text) {
  std::ofstream(path) << text;
  return path;
}

inline std::filesystem::path mesh_fixture(const std::string& name) {
  return std::filesystem::path(PHYXEL_SOURCE_DIR) / "tests/data/meshes" / name;
}

// Runs `body`, expects a SceneError and returns its message.
template <class F>
std::string scene_error(F&& body) {
  try {
    body();
  } catch (const SceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no SceneError thrown";
  return {};
}

}  // namespace phyxel::test
