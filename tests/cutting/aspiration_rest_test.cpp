// Aspiration's new surfaces in rest space (engine/surgery/aspiration.h, map_fracture_to_rest):
// on a block deformed by an affine motion x = (I + G) x0 (which the MLS gradient reproduces
// exactly), the exposed normals, carried through F^-T as the renderer carries them, are the
// crater wall's current normals, and the centre and axis move to the mouth and its axis.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <vector>

#include "engine/solver/mls_model.h"
#include "engine/surgery/aspiration.h"
#include "tests/cutting/cutting_fixtures.h"

namespace phyxel {
namespace {

// The condition number of phyxel i's moment matrix over its neighbours not in `gone`.
double condition_without(const PhyxelSet& set, const NeighbourLists& nbr, uint32_t i,
                         const std::vector<uint8_t>& gone) {
  const double h = set.objects[set.object[i]].support_radius;
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  for (uint32_t e = nbr.offset[i]; e < nbr.offset[i + 1]; ++e) {
    const uint32_t j = nbr.index[e];
    if (gone[j]) continue;
    const Vec3 x = (set.rest[j] - set.rest[i]) / h;
    const double q = std::max(0.0, 1 - x.squaredNorm());
    a += q * q * q * x * x.transpose();
  }
  return regularised_inverse(a).condition;
}

TEST(AspirationRestSpace, ADeformedBlocksCraterIsDrawnWithItsCurrentNormals) {
  const Scene scene = parse_scene(test::suction_block_json(100), "block.json");
  const PhyxelSet set = sample_scene(scene);
  std::unique_ptr<Solver> solver = make_cpu_solver(set, Vec3::Zero(), 1);
  const Eigen::Matrix3d g =
      (Eigen::Matrix3d() << 0.12, 0.15, 0.05, 0.0, -0.06, 0.10, 0.08, -0.05, 0.20).finished();
  const Eigen::Matrix3d f = Eigen::Matrix3d::Identity() + g;
  const Eigen::Matrix3d f_inv_t = f.inverse().transpose();  // normals' map, as the renderer's
  std::vector<Vec3> u(set.size());
  for (size_t i = 0; i < set.size(); ++i) u[i] = g * set.rest[i];
  solver->principal_stress()->set_principal_stress(true);
  solver->set_state(u, std::vector<Vec3>(set.size(), Vec3::Zero()));
  // The mouth 1.7 mm above the deformed top's middle, along its deformed normal.
  const ToolPose mouth{f * Vec3(0.01, 0.01, 0.0117), (f_inv_t * Vec3::UnitZ()).normalized()};
  Aspirator aspirator(scene, set);
  const std::vector<AspirationEvent> events = aspirator.after_advance(*solver, {mouth}, 0.01);
  ASSERT_EQ(events.size(), 1u);
  const AspirationEvent& e = events[0];
  ASSERT_FALSE(e.removed.empty());
  ASSERT_FALSE(e.exposed.empty());
  // The rest centre and axis move to the mouth and its axis.
  EXPECT_LT((f * e.centre - mouth.position).norm(), 1e-12);
  EXPECT_LT(((f * e.axis).normalized() - mouth.axis).norm(), 1e-12);
  EXPECT_NEAR(e.rest_radius, (set.rest[e.breaking] - e.centre).norm(), 1e-15);
  // Each wall normal as drawn, F^-T n0: the direction from the phyxel to the mouth. Where the
  // aspiration left a phyxel too few neighbours the deform pass regularises its gradient
  // (F is not I + G there): those are left out.
  std::vector<uint8_t> gone(set.size(), 0);
  for (const uint32_t k : e.removed) gone[k] = 1;
  const NeighbourLists& nbr = solver->neighbours();
  size_t checked = 0;
  for (size_t k = 0; k < e.exposed.size(); ++k) {
    const uint32_t i = e.exposed[k];
    if (condition_without(set, nbr, i, gone) > kMaxMomentCondition) continue;
    ++checked;
    const Vec3 drawn = (f_inv_t * e.exposed_normal[k]).normalized();
    const Vec3 wall = (mouth.position - (set.rest[i] + u[i])).normalized();
    EXPECT_LT((drawn - wall).norm(), 1e-12) << "phyxel " << i;
  }
  EXPECT_GT(2 * checked, e.exposed.size()) << checked << " of " << e.exposed.size();
}

}  // namespace
}  // namespace phyxel
