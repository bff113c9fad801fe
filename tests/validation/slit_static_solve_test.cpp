// tools/slit_static_solve's stabilised conforming gradients (docs/cutting.md, "Stiffness of a cut
// body") are exact for a linear displacement on the cells at the body's surface as inside: the
// whole beam's softness under SCNI is not the surface's one-sided MLS.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "tests/support/support.h"

namespace phyxel {
namespace {

TEST(SlitStaticSolve, SmoothedGradientsPassTheLinearPatchTestOnSurfaceCells) {
  for (const std::string args : {"--scni 1", "--scni 2", "--scni 2 --subcells 2"}) {
    const std::string command = std::string("cd ") + PHYXEL_SOURCE_DIR + " && " +
                                PHYXEL_BINARY_DIR + "/tools/slit_static_solve 5 --whole --patch " +
                                args;
    FILE* pipe = popen(command.c_str(), "r");
    ASSERT_NE(pipe, nullptr) << command;
    char line[256] = {};
    double interior = 1, surface = 1;
    const bool read = std::fgets(line, sizeof line, pipe) != nullptr &&
                      std::sscanf(line,
                                  "patch test, largest |G - A| / |A|: interior cells %lf, "
                                  "surface cells %lf",
                                  &interior, &surface) == 2;
    EXPECT_EQ(test::exit_status(pclose(pipe)), 0) << command;
    ASSERT_TRUE(read) << command << ": " << line;
    EXPECT_LT(interior, 1e-9) << args;
    EXPECT_LT(surface, 1e-9) << args;
  }
}

}  // namespace
}  // namespace phyxel
