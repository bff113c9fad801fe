#include "render/environment_map.h"

#include <algorithm>
#include <cmath>

namespace phyxel::render {

Eigen::Vector2d environment_st(const Vec3& d, double k) {
  const double m = d.cwiseAbs().maxCoeff();
  const Vec3 q = m > 0 ? Vec3(d / m) : Vec3(0, 0, 1);  // on the cube of half side 1 (D = 2)
  const double outer = std::sqrt(k + 4 / k);           // the texture plane's half side
  double scale;
  if (std::abs(d.z()) > std::max(std::abs(d.x()), std::abs(d.y()))) {
    scale = std::sqrt(k);  // the top face, and the bottom face as its mirror image
  } else {
    // Eqs 33-34 with D = 2: sqrt(K D^2 / 4 + D^2 / (2K) - D z / K) = sqrt(K + 2/K - 2z/K).
    scale = std::sqrt(std::max(k + 2 / k - 2 * q.z() / k, 0.0));
  }
  return {0.5 + 0.5 * q.x() * scale / outer, 0.5 + 0.5 * q.y() * scale / outer};
}

Eigen::Matrix3d environment_basis(const Camera& camera) {
  Eigen::Matrix3d m;
  m.row(0) = camera.right().transpose();
  m.row(1) = -camera.true_up().transpose();
  m.row(2) = camera.forward().transpose();
  return m;
}

RgbaImage load_environment(const std::filesystem::path& file, const std::string& context) {
  RgbaImage image = load_image(file, context);
  if (image.width != image.height) {
    throw SceneError(context + ": the environment image \"" + file.string() + "\" is " +
                     std::to_string(image.width) + " x " + std::to_string(image.height) +
                     " pixels; allowed a square image (width = height): its middle square goes "
                     "on the cube's top face and the ring around it on the sides");
  }
  return image;
}

std::vector<double> material_mirrors(const Scene& scene) {
  std::vector<double> mirror;
  for (const ObjectDesc& object : scene.objects) mirror.push_back(object.mirror);
  for (const ObjectDesc& object : scene.objects)
    for (const Inclusion& inclusion : object.inclusions) mirror.push_back(inclusion.mirror);
  return mirror;
}

}  // namespace phyxel::render
