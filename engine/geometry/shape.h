// Geometry queries on scene shapes: inside test and bounding box.
#pragma once

#include <Eigen/Geometry>

#include "engine/scene/scene.h"

namespace phyxel {

// True when p lies inside or on the boundary of the shape (boundary tolerance `eps`, m).
bool shape_contains(const Shape& shape, const Vec3& p, double eps = 0);
// Axis-aligned bounding box of the shape.
Eigen::AlignedBox3d shape_bounds(const Shape& shape);

}  // namespace phyxel
