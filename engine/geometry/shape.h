// Scene shapes (the data the scene reader fills) and their queries: inside test and bounding
// box.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "engine/geometry/vec3.h"

namespace phyxel {

// A closed triangle surface (from an OBJ, STL or PLY file), already scaled. See
// engine/geometry/mesh.h.
struct TriangleMesh;
// The voxels of a NIfTI image selected by labels or a threshold, placed in world space. See
// engine/geometry/image_volume.h.
class LabelMask;

struct Shape {
  enum class Type { Box, Sphere, Ellipsoid, Mesh, Image };
  Type type = Type::Box;
  Vec3 min = Vec3::Zero(), max = Vec3::Zero();  // box
  Vec3 center = Vec3::Zero();                   // sphere, ellipsoid
  double radius = 0;                            // sphere
  Vec3 radii = Vec3::Zero();                    // ellipsoid
  std::filesystem::path path;                   // mesh, image: resolved against the scene's folder
  double scale = 1;                             // mesh
  std::shared_ptr<const TriangleMesh> mesh;     // mesh: loaded while the scene is read
  std::vector<int64_t> labels;                  // image: voxel values inside (or threshold)
  std::optional<double> threshold;              // image: scaled values >= this are inside
  std::optional<int64_t> frame;                 // image: the frame of a 4D file
  std::shared_ptr<const LabelMask> image;       // image: built while the scene is read
};

// True when p lies inside or on the boundary of the shape (boundary tolerance `eps`, m).
bool shape_contains(const Shape& shape, const Vec3& p, double eps = 0);
// Axis-aligned bounding box of the shape.
Eigen::AlignedBox3d shape_bounds(const Shape& shape);

}  // namespace phyxel
