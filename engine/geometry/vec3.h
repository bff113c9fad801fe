// The engine's 3D vector (double), shared by every layer.
#pragma once

#include <Eigen/Core>

namespace phyxel {

using Vec3 = Eigen::Vector3d;

}  // namespace phyxel
