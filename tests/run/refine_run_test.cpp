// `phyxel run --refine K` end to end: the finer set, its time step and summary.json's refine;
// a bad K is a usage error naming the option.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "tests/physics/physics_fixtures.h"
#include "tests/support/support.h"

namespace phyxel {
namespace {

using phyxel::test::read_text;

// Runs the phyxel binary; returns the exit status and its stderr.
std::pair<int, std::string> run_phyxel(const std::string& args, const std::string& tag) {
  const std::filesystem::path err = test::test_output_dir("refine_stderr_" + tag) / "stderr.txt";
  const test::Ran ran = test::run_phyxel(args, err);
  return {ran.status, ran.err};
}

const std::string kBeam = std::string(PHYXEL_SOURCE_DIR) + "/scenes/beam.json";

nlohmann::json run_beam(double refine, const std::string& tag) {
  const auto dir = test::test_output_dir("refine_" + tag);
  std::ostringstream args;
  args << "run " << kBeam << " --steps 1 --threads 1 --refine " << refine << " --out "
       << dir.string();
  const auto [code, err] = run_phyxel(args.str(), tag);
  EXPECT_EQ(code, 0) << err;
  return nlohmann::json::parse(read_text(dir / "summary.json"));
}

TEST(PhyxelRunRefine, FinerSetSmallerStepSameScene) {
  const nlohmann::json coarse = run_beam(1, "k1"), fine = run_beam(2, "k2");
  EXPECT_EQ(coarse["refine"].get<double>(), 1);
  EXPECT_EQ(fine["refine"].get<double>(), 2);
  const double s1 = coarse["objects"][0]["spacing"], s2 = fine["objects"][0]["spacing"];
  EXPECT_DOUBLE_EQ(s2, s1 / 2);
  EXPECT_DOUBLE_EQ(fine["objects"][0]["support_radius"].get<double>(),
                   coarse["objects"][0]["support_radius"].get<double>() / 2);
  // 41 x 9 x 9 lattice sites at 2.5 mm; 81 x 17 x 17 at 1.25 mm.
  EXPECT_EQ(coarse["phyxels"], 41 * 9 * 9);
  EXPECT_EQ(fine["phyxels"], 81 * 17 * 17);
  // The same requested step, the stable bound halved with the spacing.
  EXPECT_EQ(fine["dt_requested"], coarse["dt_requested"]);
  EXPECT_NEAR(fine["dt_stable_bound"].get<double>(), coarse["dt_stable_bound"].get<double>() / 2,
              1e-15);
  EXPECT_GE(fine["substeps_per_step"].get<int>(), 2 * coarse["substeps_per_step"].get<int>() - 1);
}

TEST(PhyxelRunRefine, BadFactorIsAUsageErrorNamingTheOption) {
  for (const char* k : {"0.5", "0", "-1", "abc", "nan", "100"}) {
    const auto [code, err] = run_phyxel("run " + kBeam + " --refine " + k, "bad");
    EXPECT_EQ(code, 2) << k;
    EXPECT_NE(err.find("--refine"), std::string::npos) << k << ": " << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  }
  const auto [code, err] = run_phyxel("view " + kBeam + " --refine 0.9", "view");
  EXPECT_EQ(code, 2);
  EXPECT_NE(err.find("--refine"), std::string::npos) << err;
}

}  // namespace
}  // namespace phyxel
