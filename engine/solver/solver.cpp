#include "engine/solver/solver.h"

#include <algorithm>
#include <string>

namespace phyxel {

void Solver::advance_paused(int64_t, double, const std::vector<int64_t>&,
                            const std::function<void(int64_t)>&) {
  throw std::logic_error(device() + " cannot pause inside an advance");
}

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

NearState Solver::read_near(const PhyxelSet& set, const Bounds& box) {
  const PointState s = read_state(true);
  const std::vector<Vec3>& u = s.displacement;
  const std::vector<double>& principal = s.max_principal_stress;
  if (u.size() != set.size())
    throw std::invalid_argument("Solver::read_near: the set has " + std::to_string(set.size()) +
                                " phyxels, the solver " + std::to_string(u.size()));
  NearState near;
  for (size_t i = 0; i < u.size(); ++i) {
    const Vec3 x = set.rest[i] + u[i];
    if ((x.array() < box.min.array()).any() || (x.array() > box.max.array()).any()) continue;
    near.ids.push_back(static_cast<uint32_t>(i));
    near.displacement.push_back(u[i]);
    if (principal.size() == u.size()) near.principal.push_back(principal[i]);
  }
  return near;
}

std::vector<Vec3> Solver::read_displacements(const std::vector<uint32_t>& ids) {
  const std::vector<Vec3> u = read_state(false).displacement;
  std::vector<Vec3> out;
  out.reserve(ids.size());
  for (const uint32_t i : ids) out.push_back(u.at(i));
  return out;
}

}  // namespace phyxel
