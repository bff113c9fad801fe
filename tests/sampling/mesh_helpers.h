// OBJ fixtures generated in the tests: icospheres and variants of the unit cube.
#pragma once

#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "engine/geometry/mesh.h"
#include "engine/scene/scene.h"
#include "sampling_helpers.h"

namespace phyxel::test {

// OBJ text of an icosphere of radius 1: an icosahedron subdivided `levels` times (20 * 4^levels
// outward triangles), vertices projected onto the sphere.
inline std::string icosphere_obj(int levels) {
  const double t = (1 + std::sqrt(5.0)) / 2;
  std::vector<Vec3> v = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                         {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (Vec3& p : v) p.normalize();
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<int, int>, int> midpoints;
    auto mid = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = midpoints.find(key);
      if (it != midpoints.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      midpoints.emplace(key, int(v.size()) - 1);
      return int(v.size()) - 1;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& [a, b, c] : f) {
      const int ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
      next.insert(next.end(), {{a, ab, ca}, {b, bc, ab}, {c, ca, bc}, {ab, bc, ca}});
    }
    f = std::move(next);
  }
  std::ostringstream obj;
  obj.precision(17);
  for (const Vec3& p : v) obj << "v " << p.x() << " " << p.y() << " " << p.z() << "\n";
  for (const auto& [a, b, c] : f) obj << "f " << a + 1 << " " << b + 1 << " " << c + 1 << "\n";
  return obj.str();
}

// The unit cube of tests/data/meshes/cube.obj, with its faces written as `faces`.
inline std::string cube_obj(const std::string& faces) {
  return "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n" + faces;
}

inline const char* kCubeFaces =
    "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

// An L-shaped prism, non-convex: the L with corners (0,0) (2,0) (2,1) (1,1) (1,2) (0,2) in xy,
// from z = 0 to 1. The union of the boxes [0,2]x[0,1]x[0,1] and [0,1]x[0,2]x[0,1].
inline std::string l_prism_obj() {
  const int xy[6][2] = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  std::ostringstream obj;
  for (int z = 0; z < 2; ++z)
    for (const auto& p : xy) obj << "v " << p[0] << " " << p[1] << " " << z << "\n";
  // Caps: a fan from the concave corner (vertex 4 below, 10 above); the bottom one faces -z.
  for (const auto& [a, b] : {std::pair{5, 6}, {6, 1}, {1, 2}, {2, 3}}) {
    obj << "f 4 " << b << " " << a << "\n";
    obj << "f 10 " << a + 6 << " " << b + 6 << "\n";
  }
  for (int k = 1; k <= 6; ++k) {  // sides: quads along the counter-clockwise outline
    const int n = k % 6 + 1;
    obj << "f " << k << " " << n << " " << n + 6 << " " << k + 6 << "\n";
  }
  return obj.str();
}

// The message of loading a mesh file (OBJ, STL or PLY) that must fail.
inline std::string load_error(const std::filesystem::path& path) {
  try {
    load_mesh(path, 1);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error loading " << path;
  return {};
}

inline Shape mesh_shape(const std::shared_ptr<const TriangleMesh>& mesh) {
  Shape s;
  s.type = Shape::Type::Mesh;
  s.mesh = mesh;
  return s;
}

}  // namespace phyxel::test
