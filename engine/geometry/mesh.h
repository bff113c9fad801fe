// Closed triangle surfaces read from OBJ files (tinyobjloader), with an inside test.
#pragma once

#include <Eigen/Geometry>
#include <filesystem>
#include <vector>

#include "engine/scene/scene.h"

namespace phyxel {

struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<Eigen::Vector3i> triangles;
  Eigen::AlignedBox3d bounds;
  // Inside test for a closed surface (generalised winding number > 0.5).
  bool contains(const Vec3& p) const;
};

// Loads an OBJ file and scales it. Throws std::runtime_error with a one-line reason
// (missing file, parse error, no triangles, not closed); the scene loader adds the JSON path.
TriangleMesh load_obj_mesh(const std::filesystem::path& path, double scale);

}  // namespace phyxel
