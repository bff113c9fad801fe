// refine_scene (scene.h): the same scene sampled K times finer.
#include <cmath>
#include <stdexcept>
#include <string>

#include "engine/scene/scene.h"

namespace phyxel {

void refine_scene(Scene& scene, double factor) {
  if (!std::isfinite(factor) || factor < 1 || factor > kMaxRefine)
    throw std::invalid_argument("refine " + std::to_string(factor) +
                                ": expected a number from 1 to " + std::to_string(kMaxRefine));
  for (ObjectDesc& o : scene.objects) {
    o.spacing /= factor;
    o.support_radius /= factor;
  }
  scene.refine *= factor;
}

}  // namespace phyxel
