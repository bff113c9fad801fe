// Inside tests and bounds of scene shapes.
#include "engine/geometry/shape.h"

#include <cmath>

#include "engine/geometry/image_volume.h"
#include "engine/geometry/mesh.h"
#include "engine/geometry/mesh_query.h"

namespace phyxel {

bool shape_contains(const Shape& shape, const Vec3& p, double eps) {
  switch (shape.type) {
    case Shape::Type::Box:
      return (p.array() >= shape.min.array() - eps).all() &&
             (p.array() <= shape.max.array() + eps).all();
    case Shape::Type::Sphere:
      return (p - shape.center).norm() <= shape.radius + eps;
    case Shape::Type::Ellipsoid: {
      // f = sum (q_d / r_d)^2 is 1 on the surface; (f - 1) / |grad f| is the first-order
      // distance to it, which decides the boundary band.
      const Vec3 q = (p - shape.center).cwiseQuotient(shape.radii);
      const double f = q.squaredNorm();
      if (f <= 1) return true;
      const double grad = 2 * q.cwiseQuotient(shape.radii).norm();
      return f - 1 <= eps * grad;
    }
    case Shape::Type::Mesh:
      if (!shape.mesh) return false;
      return shape.mesh->contains(p) || (eps > 0 && surface_distance_direct(*shape.mesh, p) <= eps);
    case Shape::Type::Image:
      return shape.image && shape.image->contains(p);
  }
  return false;
}

Eigen::AlignedBox3d shape_bounds(const Shape& shape) {
  switch (shape.type) {
    case Shape::Type::Box:
      return Eigen::AlignedBox3d(shape.min, shape.max);
    case Shape::Type::Sphere:
      return Eigen::AlignedBox3d(shape.center - Vec3::Constant(shape.radius),
                                 shape.center + Vec3::Constant(shape.radius));
    case Shape::Type::Ellipsoid:
      return Eigen::AlignedBox3d(shape.center - shape.radii, shape.center + shape.radii);
    case Shape::Type::Mesh:
      return shape.mesh ? shape.mesh->bounds : Eigen::AlignedBox3d();
    case Shape::Type::Image:
      return shape.image ? shape.image->bounds() : Eigen::AlignedBox3d();
  }
  return Eigen::AlignedBox3d();
}

}  // namespace phyxel
