#include "engine/scene/scene_limits.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "engine/geometry/shape.h"

namespace phyxel {

using json_reader::format_approx;
using json_reader::format_number;

void check_time_step(const json_reader::Node& root, const Scene& scene) {
  double bound = std::numeric_limits<double>::infinity();
  std::string stiffest;  // the object and material that set the bound
  for (const ObjectDesc& o : scene.objects) {
    std::vector<std::pair<std::string, const Material*>> materials = {{o.name, &o.material}};
    for (const Inclusion& inc : o.inclusions)
      materials.push_back({o.name + "/" + inc.name, &inc.material});
    for (const auto& [name, m] : materials) {
      const double step = scene.simulation.courant * o.spacing / p_wave_speed(*m);
      if (!(step >= bound)) {
        bound = step;
        stiffest = name;
      }
    }
  }
  const double substeps = scene.simulation.dt / bound;
  if (!(bound > 0) || !(substeps <= kMaxSubstepsPerStep)) {
    const json_reader::Node dt = root.at("simulation", "").at("dt", "");
    dt.fail(format_number(scene.simulation.dt) + " s needs " + format_approx(substeps) +
                " substeps per step (the stable step of '" + stiffest + "' is " +
                format_approx(bound) + " s: courant x spacing / p-wave speed)",
            "allowed dt <= " + format_approx(kMaxSubstepsPerStep * bound) + " s (" +
                format_approx(kMaxSubstepsPerStep) +
                " substeps); lower dt, or check the material's young, density and poisson");
  }
}

void check_tool_sizes(const json_reader::Node& root, const Scene& scene) {
  if (scene.tools.empty()) return;
  Eigen::AlignedBox3d bounds;
  for (const ObjectDesc& o : scene.objects) bounds.extend(shape_bounds(o.shape));
  const double extent = bounds.isEmpty() ? 0.0 : bounds.diagonal().norm();
  const double limit = kMaxToolToScene * extent;
  const std::vector<json_reader::Node> nodes = root.at("tools", "").elements("");
  for (size_t k = 0; k < scene.tools.size() && k < nodes.size(); ++k) {
    const ToolShape& s = scene.tools[k].shape;
    for (const char* key : {"radius", "length"}) {
      const double size = key[0] == 'r' ? s.radius : s.length;
      if (size <= limit) continue;
      const json_reader::Node shape = nodes[k].at("shape", "");
      shape.at(key, "").fail(
          "tool '" + scene.tools[k].name + "' has a " + key + " of " + format_number(size) +
              " m against a scene of " + format_approx(extent) +
              " m (the diagonal of the objects' bounds); a unit slip (mm for m)?",
          "allowed " + std::string(key) + " <= " + format_approx(limit) + " m (" +
              format_approx(kMaxToolToScene) + " x the scene's extent)");
    }
  }
}

}  // namespace phyxel
