// Kernel normalisation and support; rest neighbour lists against brute force.
#include <gtest/gtest.h>

#include <atomic>
#include <numbers>

#include "engine/solver/kernel.h"
#include "engine/solver/neighbours.h"
#include "engine/solver/solver.h"
#include "tests/physics/physics_fixtures.h"

namespace phyxel {
namespace {

TEST(Kernel, IntegratesToOneOverItsSupport) {
  for (double h : {0.001, 0.01, 1.0}) {
    // 4 pi int_0^h w(r) r^2 dr by the composite Simpson rule.
    const int n = 2000;
    double sum = 0;
    for (int k = 0; k <= n; ++k) {
      const double r = h * k / n;
      const double weight = (k == 0 || k == n) ? 1 : (k % 2 ? 4 : 2);
      sum += weight * poly6(r * r, h) * r * r;
    }
    const double integral = 4 * std::numbers::pi * sum * (h / n) / 3;
    EXPECT_NEAR(integral, 1.0, 1e-9) << "h = " << h;
  }
}

TEST(Kernel, VanishesAtAndBeyondTheSupportAndDecreases) {
  const double h = 0.02;
  EXPECT_EQ(poly6(h * h, h), 0.0);
  EXPECT_EQ(poly6(4 * h * h, h), 0.0);
  double last = poly6(0.0, h);
  EXPECT_GT(last, 0.0);
  for (int k = 1; k < 100; ++k) {
    const double r = h * k / 100;
    const double w = poly6(r * r, h);
    EXPECT_GT(w, 0.0);
    EXPECT_LT(w, last);
    last = w;
  }
}

TEST(Neighbours, SymmetricSortedAndEqualToBruteForce) {
  const Scene scene =
      test::box_scene(Vec3(0, 0, 0), Vec3(0.03, 0.02, 0.017), 0.0025, test::tissue(), 2.3);
  const PhyxelSet set = sample_scene(scene);
  const NeighbourLists nbr = find_rest_neighbours(set);
  const double h = set.objects[0].support_radius;
  ASSERT_EQ(nbr.offset.size(), set.size() + 1);
  for (size_t i = 0; i < set.size(); ++i) {
    std::vector<uint32_t> brute;
    for (size_t j = 0; j < set.size(); ++j)
      if (j != i && (set.rest[j] - set.rest[i]).squaredNorm() < h * h * (1 - 1e-9))
        brute.push_back(j);
    const std::vector<uint32_t> got(nbr.index.begin() + nbr.offset[i],
                                    nbr.index.begin() + nbr.offset[i + 1]);
    ASSERT_EQ(got, brute) << "phyxel " << i;
    for (uint32_t j : got) {
      const auto b = nbr.index.begin() + nbr.offset[j], e = nbr.index.begin() + nbr.offset[j + 1];
      EXPECT_TRUE(std::binary_search(b, e, static_cast<uint32_t>(i)));
    }
  }
}

TEST(Neighbours, DefaultSupportGivesTheFullStencilInside) {
  const Scene scene =
      test::box_scene(Vec3(0, 0, 0), Vec3(0.02, 0.02, 0.02), 0.0025, test::tissue());
  const PhyxelSet set = sample_scene(scene);
  const NeighbourLists nbr = find_rest_neighbours(set);
  uint32_t most = 0;
  for (size_t i = 0; i < set.size(); ++i) most = std::max(most, nbr.count(i));
  EXPECT_EQ(most, 26u);  // h = 2 s: the 3x3x3 block (distance 2 s itself has zero weight)
}

TEST(Neighbours, SeparateObjectsNeverNeighbour) {
  Scene scene = test::box_scene(Vec3(0, 0, 0), Vec3(0.01, 0.01, 0.01), 0.0025, test::tissue());
  ObjectDesc second = scene.objects[0];
  second.name = "touching";
  second.shape = test::box_shape(Vec3(0.0125, 0, 0), Vec3(0.0225, 0.01, 0.01));
  scene.objects.push_back(second);
  const PhyxelSet set = sample_scene(scene);
  const NeighbourLists nbr = find_rest_neighbours(set);
  for (size_t i = 0; i < set.size(); ++i)
    for (uint32_t k = nbr.offset[i]; k < nbr.offset[i + 1]; ++k)
      EXPECT_EQ(set.object[i], set.object[nbr.index[k]]);
}

// The search polls its stop every 256 phyxels (the first of each chunk), and a stop ends it with
// SearchStopped; without a stop it finds what it always finds.
TEST(Neighbours, TheSearchPollsItsStopAndEndsOnIt) {
  const Scene scene =
      test::box_scene(Vec3(0, 0, 0), Vec3(0.03, 0.02, 0.017), 0.0025, test::tissue(), 2.3);
  const PhyxelSet set = sample_scene(scene);
  const NeighbourLists plain = find_rest_neighbours(set);
  std::atomic<int> polls{0};
  set_search_stop([&] { return ++polls < 0; });
  const NeighbourLists polled = find_rest_neighbours(set);
  EXPECT_EQ(polls.load(), int((set.size() + 255) / 256));
  EXPECT_EQ(polled.offset, plain.offset);
  EXPECT_EQ(polled.index, plain.index);
  set_search_stop([] { return true; });
  EXPECT_THROW(find_rest_neighbours(set), SearchStopped);
  set_search_stop({});
  EXPECT_EQ(find_rest_neighbours(set).index, plain.index);
}

// The CPU solver's MLS precompute polls the same stop every 256 phyxels after the search's
// polls: a stop there ends it with SearchStopped naming the precompute; without one the solver
// is built as always.
TEST(Neighbours, TheCpuPrecomputePollsTheStopAndEndsOnIt) {
  const Scene scene =
      test::box_scene(Vec3(0, 0, 0), Vec3(0.03, 0.02, 0.017), 0.0025, test::tissue(), 2.3);
  const PhyxelSet set = sample_scene(scene);
  const int search_polls = int((set.size() + 255) / 256);
  ASSERT_GT(search_polls, 1);
  std::atomic<int> polls{0};
  set_search_stop([&] { return ++polls < 0; });
  const auto plain = make_cpu_solver(set, Vec3::Zero(), 1);
  EXPECT_EQ(polls.load(), 2 * search_polls);  // the search's, then the precompute's
  polls = 0;
  set_search_stop([&] { return ++polls > search_polls; });  // the search runs to its end
  try {
    make_cpu_solver(set, Vec3::Zero(), 1);
    ADD_FAILURE() << "the precompute did not stop";
  } catch (const SearchStopped& e) {
    EXPECT_STREQ(e.what(), "stopped during the MLS precompute");
  }
  EXPECT_EQ(polls.load(), search_polls + 1);  // one thread: the precompute's first poll ended it
  set_search_stop({});
  EXPECT_EQ(make_cpu_solver(set, Vec3::Zero(), 1)->neighbours().index, plain->neighbours().index);
}

}  // namespace
}  // namespace phyxel
