// Closed triangle surfaces read from OBJ (tinyobjloader), STL and PLY files (assimp), with an
// inside test.
#pragma once

#include <Eigen/Geometry>
#include <filesystem>
#include <string>
#include <vector>

#include "engine/geometry/vec3.h"

namespace phyxel {

struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<Eigen::Vector3i> triangles;
  Eigen::AlignedBox3d bounds;
  // Inside test for a closed surface (generalised winding number > 0.5).
  bool contains(const Vec3& p) const;
};

// Loads a mesh file by its extension (.obj, .stl binary or ASCII, .ply) and scales it. Throws
// std::runtime_error with a one-line reason (missing file, unsupported format, parse error, no
// triangles, not closed); the scene loader adds the JSON path.
TriangleMesh load_mesh(const std::filesystem::path& path, double scale);
// The same for one format: OBJ, or "STL" / "PLY" through assimp.
TriangleMesh load_obj_mesh(const std::filesystem::path& path, double scale);
// An OBJ file's text already in memory; `path` only names it in messages (nothing is read).
TriangleMesh parse_obj_mesh(const std::string& text, const std::filesystem::path& path,
                            double scale);
TriangleMesh load_assimp_mesh(const std::filesystem::path& path, double scale,
                              const std::string& format);

}  // namespace phyxel
