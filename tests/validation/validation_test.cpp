// The validation scenes meet their references at the default resolution, and their errors
// fall as the resolution rises (issue: fast and accurate).
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "engine/run/validation.h"

namespace phyxel {
namespace {

const ValidationCase& find_case(const std::string& name) {
  static const std::vector<ValidationCase> cases = validation_cases(PHYXEL_SOURCE_DIR);
  for (const ValidationCase& c : cases)
    if (c.name == name) return c;
  throw std::runtime_error("no validation case " + name);
}

ValidationRun run_cpu(const std::string& name, double spacing_scale, double dt_fraction = 1.0) {
  const SolverFactory cpu = [](const PhyxelSet& set, const Vec3& g) {
    return make_cpu_solver(set, g, 1);
  };
  return run_validation(find_case(name), spacing_scale, dt_fraction, cpu);
}

TEST(Validation, CantileverSmallDeflectionWithinFivePercentOfCalculix) {
  const ValidationRun r = run_cpu("cantilever_small", 1.0);
  ASSERT_TRUE(r.finite);
  EXPECT_LT(r.error, 0.05) << "tip u_z " << r.value << " CalculiX " << r.reference;
}

double calculix(const char* which, const char* quantity) {
  std::ifstream in(std::string(PHYXEL_SOURCE_DIR) + "/scenes/validation/cantilever_reference.json");
  return nlohmann::json::parse(in)["cases"][which]["results"][quantity].get<double>();
}

TEST(Validation, CantileverLargeDeflectionFollowsStVenantKirchhoffNotLinearElasticity) {
  const ValidationRun r = run_cpu("cantilever_large", 1.0);
  ASSERT_TRUE(r.finite);
  EXPECT_LT(r.error, 0.05) << "tip u_z " << r.value << " CalculiX NLGEOM " << r.reference;
  // Closer to the nonlinear than to the linear answer (they differ by 5.5 %) ...
  const double linear = calculix("C-lin", "tip_center_uz");
  EXPECT_LT(std::abs(r.value - r.reference), std::abs(r.value - linear));
  // ... and the tip is pulled back along the beam, which linear elasticity cannot do.
  const double pull_back = calculix("C-nl", "tip_center_ux");
  EXPECT_NEAR(r.secondary / pull_back, 1.0, 0.10)
      << "tip u_x " << r.secondary << " CalculiX NLGEOM " << pull_back;
}

TEST(Validation, SlitCantileverAgainstCalculixAndTheErrorFallsWithTheSpacing) {
  // A half-depth slit cut by the scalpel at rest, then loaded (docs/cutting.md, "Stiffness of
  // a cut body"). The cut body is still too compliant, by 19.9 % at 2.86 mm and 30.6 % at 4 mm
  // (28.0 and 44.7 % while rounding severed half the pairs through the crack front): the MLS
  // fit and nodal integration round the front make the slit act about half a spacing deeper.
  // This bounds it from both sides and checks that it shrinks.
  const ValidationRun fine = run_cpu("cantilever_slit", 1.0);
  const ValidationRun coarse = run_cpu("cantilever_slit", 1.4);  // 0.02 / 5
  ASSERT_TRUE(fine.finite && coarse.finite);
  for (const ValidationRun& r : {coarse, fine})
    std::printf("[ slit     ] spacing %.4g m: tip u_z %.6g m, CalculiX %.6g m, error %.4f\n",
                r.spacing, r.value, r.reference, r.error);
  EXPECT_GT(fine.value / fine.reference, 1.0) << "tip u_z " << fine.value;
  EXPECT_LT(fine.error, 0.21) << "tip u_z " << fine.value << " CalculiX " << fine.reference;
  EXPECT_LT(fine.error, 0.7 * coarse.error) << "spacing " << coarse.spacing << ": " << coarse.error
                                            << ", spacing " << fine.spacing << ": " << fine.error;
}

TEST(Validation, UniaxialStretchRecoversYoungsModulusAndPoissonRatio) {
  const ValidationRun r = run_cpu("uniaxial_bar", 1.0);
  ASSERT_TRUE(r.finite);
  EXPECT_LT(r.error, 0.02) << "E " << r.value << " expected " << r.reference << ", nu "
                           << r.secondary;
}

TEST(Validation, WaveSpeedWithinFivePercentOfPWaveSpeed) {
  const ValidationRun r = run_cpu("wave_bar", 1.0);
  ASSERT_TRUE(r.finite);
  EXPECT_GT(r.value, 0) << "no front arrived";
  EXPECT_LT(r.error, 0.05) << "front speed " << r.value << " c_p " << r.reference;
}

TEST(Validation, CantileverErrorFallsAsResolutionRises) {
  const ValidationRun coarse = run_cpu("cantilever_small", 2.0);
  const ValidationRun fine = run_cpu("cantilever_small", 1.0);
  EXPECT_LT(fine.error, coarse.error) << "spacing " << coarse.spacing << ": " << coarse.error
                                      << ", spacing " << fine.spacing << ": " << fine.error;
}

TEST(Validation, WaveSpeedErrorFallsAsResolutionRises) {
  const ValidationRun coarse = run_cpu("wave_bar", 2.0);
  const ValidationRun fine = run_cpu("wave_bar", 1.0);
  EXPECT_LT(fine.error, coarse.error) << "spacing " << coarse.spacing << ": " << coarse.error
                                      << ", spacing " << fine.spacing << ": " << fine.error;
}

}  // namespace
}  // namespace phyxel
