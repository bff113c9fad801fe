#include "engine/solver/solver.h"

#include <algorithm>

namespace phyxel {

std::pair<double, double> Solver::max_norms() {
  const PointState s = read_state(false);
  double u = 0, v = 0;
  for (const Vec3& x : s.displacement) u = std::max(u, x.norm());
  for (const Vec3& x : s.velocity) v = std::max(v, x.norm());
  return {u, v};
}

std::vector<ObjectMotion> Solver::object_motion(const PhyxelSet& set) {
  return sum_object_motion(set, read_state(false).velocity);
}

}  // namespace phyxel
