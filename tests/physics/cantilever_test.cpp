// Cantilever under gravity against CalculiX (scenes/validation/cantilever_reference.json,
// made by scenes/validation/ccx/make_cantilever_reference.sh): small deflection within 5 %,
// and large deflection that follows St Venant-Kirchhoff (geometric nonlinearity), not
// linear elasticity.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "engine/cpu_solver.h"
#include "engine/simulation.h"
#include "tests/physics/physics_fixtures.h"

namespace phyxel {
namespace {

nlohmann::json reference() {
  std::ifstream in(std::string(PHYXEL_SOURCE_DIR) + "/scenes/validation/cantilever_reference.json");
  EXPECT_TRUE(in.good());
  return nlohmann::json::parse(in);
}

double ref_value(const nlohmann::json& ref, const char* name, const char* quantity) {
  return ref["cases"][name]["results"][quantity].get<double>();
}

struct Tip {
  Vec3 displacement;
  bool finite = true;
};

// The CalculiX beam (0.1 x 0.02 x 0.02 m, E 1 MPa, nu 0.3, rho 1000) clamped at x = 0 under
// gravity g, relaxed to rest with damping near critical for the first bending mode.
Tip cantilever_tip(double g) {
  Scene scene = test::box_scene(Vec3(0, -0.01, -0.01), Vec3(0.1, 0.01, 0.01), 0.0025,
                                test::tissue(1e6, 0.3, 130.0));
  scene.objects[0].fixed.push_back(test::box_shape(Vec3(-1, -1, -1), Vec3(0.0005, 1, 1)));
  const Vec3 gravity(0, 0, -g);
  const PhyxelSet set = sample_scene(scene);
  CpuSolver<double> solver(set, gravity);
  const double dt = plan_time_step(scene, set).dt_stable;
  size_t tip = set.size();
  for (size_t i = 0; i < set.size(); ++i)
    if ((set.rest[i] - Vec3(0.1, 0, 0)).norm() < 1e-9) tip = i;
  EXPECT_LT(tip, set.size());
  double peak = 0;
  for (int k = 0; k < 30000; ++k) {
    solver.step(dt);
    if (k % 100 == 0) {
      const double ke = solver.energies().kinetic;
      peak = std::max(peak, ke);
      if (k > 3000 && ke < 1e-10 * peak) break;
    }
  }
  return {solver.displacement()[tip], solver.first_non_finite() < 0};
}

TEST(Cantilever, SmallDeflectionMatchesCalculix) {
  const nlohmann::json ref = reference();
  const double expected = ref_value(ref, "A", "tip_center_uz");
  const Tip tip = cantilever_tip(9.81);
  ASSERT_TRUE(tip.finite);
  EXPECT_NEAR(tip.displacement.z() / expected, 1.0, 0.05)
      << "tip u_z " << tip.displacement.z() << " CalculiX " << expected;
}

TEST(Cantilever, LargeDeflectionFollowsStVenantKirchhoffNotLinearElasticity) {
  const nlohmann::json ref = reference();
  const double nl_z = ref_value(ref, "C-nl", "tip_center_uz");
  const double nl_x = ref_value(ref, "C-nl", "tip_center_ux");
  const double lin_z = ref_value(ref, "C-lin", "tip_center_uz");
  const Tip tip = cantilever_tip(78.48);
  ASSERT_TRUE(tip.finite);
  EXPECT_NEAR(tip.displacement.z() / nl_z, 1.0, 0.05)
      << "tip u_z " << tip.displacement.z() << " CalculiX NLGEOM " << nl_z;
  // Closer to the nonlinear than to the linear answer ...
  EXPECT_LT(std::abs(tip.displacement.z() - nl_z), std::abs(tip.displacement.z() - lin_z));
  // ... and the tip is pulled back along the beam, which linear elasticity cannot do.
  EXPECT_NEAR(tip.displacement.x() / nl_x, 1.0, 0.10)
      << "tip u_x " << tip.displacement.x() << " CalculiX NLGEOM " << nl_x;
}

}  // namespace
}  // namespace phyxel
