// STL (binary and ASCII) and PLY meshes through assimp: the unit cube written in each format
// samples to the OBJ cube's phyxels, and open or unreadable files are refused like OBJ ones.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <sstream>

#include "engine/geometry/mesh.h"
#include "engine/sampling/phyxel_set.h"
#include "mesh_helpers.h"

namespace phyxel::test {
namespace {

const std::array<std::array<float, 3>, 8> kCorners = {
    {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}};
// cube.obj's quads (0-based), counter-clockwise from outside.
const std::array<std::array<int, 4>, 6> kQuads = {
    {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}}};

// The quads split as tinyobjloader splits them: (0, 1, 2) and (0, 2, 3). `faces` quads only.
std::vector<std::array<int, 3>> triangles(size_t faces = kQuads.size()) {
  std::vector<std::array<int, 3>> out;
  for (size_t f = 0; f < faces; ++f) {
    const auto& q = kQuads[f];
    out.push_back({q[0], q[1], q[2]});
    out.push_back({q[0], q[2], q[3]});
  }
  return out;
}

std::filesystem::path binary_stl(const std::filesystem::path& path, size_t faces = 6) {
  const auto tris = triangles(faces);
  std::ofstream out(path, std::ios::binary);
  const std::string header(80, ' ');
  out.write(header.data(), 80);
  const uint32_t count = uint32_t(tris.size());
  out.write(reinterpret_cast<const char*>(&count), 4);
  for (const auto& t : tris) {
    float values[12] = {};
    for (int k = 0; k < 3; ++k) std::memcpy(values + 3 + 3 * k, kCorners[t[k]].data(), 12);
    out.write(reinterpret_cast<const char*>(values), sizeof values);
    const uint16_t attributes = 0;
    out.write(reinterpret_cast<const char*>(&attributes), 2);
  }
  return path;
}

std::filesystem::path ascii_stl(const std::filesystem::path& path) {
  std::ostringstream text;
  text << "solid cube\n";
  for (const auto& t : triangles()) {
    text << " facet normal 0 0 0\n  outer loop\n";
    for (int k : t)
      text << "   vertex " << kCorners[k][0] << " " << kCorners[k][1] << " " << kCorners[k][2]
           << "\n";
    text << "  endloop\n endfacet\n";
  }
  text << "endsolid cube\n";
  return write_file(path, text.str());
}

std::filesystem::path ascii_ply(const std::filesystem::path& path) {
  std::ostringstream text;
  text << "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
          "property float z\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n";
  for (const auto& c : kCorners) text << c[0] << " " << c[1] << " " << c[2] << "\n";
  for (const auto& q : kQuads)
    text << "4 " << q[0] << " " << q[1] << " " << q[2] << " " << q[3] << "\n";
  return write_file(path, text.str());
}

PhyxelSet sample_cube(const std::filesystem::path& path) {
  Shape s = mesh_shape(std::make_shared<const TriangleMesh>(load_mesh(path, 0.1)));
  return sample_scene(scene_of({object("cube", s, 0.0125)}));
}

TEST(MeshFormats, StlAndPlyCubesGiveTheObjCubesPhyxels) {
  const auto dir = test_dir();
  const PhyxelSet obj = sample_cube(mesh_fixture("cube.obj"));
  ASSERT_EQ(obj.size(), 9u * 9u * 9u);
  for (const auto& path : {binary_stl(dir / "cube.stl"), ascii_stl(dir / "cube_ascii.STL"),
                           ascii_ply(dir / "cube.ply")}) {
    SCOPED_TRACE(path.filename().string());
    const PhyxelSet set = sample_cube(path);
    ASSERT_EQ(set.size(), obj.size());
    for (size_t i = 0; i < obj.size(); ++i) {
      ASSERT_EQ(set.rest[i], obj.rest[i]) << i;
      EXPECT_EQ(set.volume[i], obj.volume[i]) << i;
      EXPECT_EQ(set.flags[i], obj.flags[i]) << i;
      EXPECT_NEAR((set.normal[i] - obj.normal[i]).norm(), 0, 1e-12) << i;
    }
  }
}

TEST(MeshFormats, OpenUnreadableAndUnknownFilesAreRefused) {
  const auto dir = test_dir();
  std::string message = load_error(binary_stl(dir / "open.stl", 5));
  EXPECT_NE(message.find("open.stl: the surface is not closed: 4 edges"), std::string::npos)
      << message;
  EXPECT_NE(message.find("STL vertices"), std::string::npos) << message;
  message = load_error(write_file(dir / "garbage.stl", "this is not a mesh"));
  EXPECT_NE(message.find("garbage.stl: cannot parse the STL file"), std::string::npos) << message;
  message = load_error(write_file(dir / "cube.3ds", "x"));
  EXPECT_NE(message.find("unsupported mesh format \".3ds\"; use a closed surface in OBJ"),
            std::string::npos)
      << message;
  for (const std::string& m : {message, load_error(dir / "missing.ply")})
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
}

TEST(MeshFormats, SceneFilesTakePlyAndStlPaths) {
  const auto dir = test_dir();
  ascii_ply(dir / "cube.ply");
  const Scene scene = parse_scene(
      R"({"simulation": {"dt": 1e-4, "steps": 1}, "objects": [{"name": "cube", "shape":
          {"type": "mesh", "path": "cube.ply", "scale": 0.1}, "spacing": 0.0125, "material":
          {"young": 3000, "poisson": 0.45, "density": 1000}}]})",
      dir / "scene.json");
  EXPECT_EQ(sample_scene(scene).size(), 9u * 9u * 9u);
}

}  // namespace
}  // namespace phyxel::test
