// bench/timing.h: the order of the calls and the medians (never the times themselves).
#include "bench/timing.h"

#include <gtest/gtest.h>

#include <string>

namespace phyxel::bench {
namespace {

TEST(BenchTiming, MedianOfOddEvenAndEmpty) {
  EXPECT_EQ(median_of({3, 1, 2}), 2);
  EXPECT_EQ(median_of({4, 1, 3, 2}), 2.5);
  EXPECT_EQ(median_of({}), 0);
}

TEST(BenchTiming, WarmUpThenRepeatsInterleaved) {
  std::string calls;
  const std::vector<Timing> t =
      time_interleaved({[&] { calls += 'a'; }, [&] { calls += 'b'; }}, 3, 1);
  EXPECT_EQ(calls, "abababab");  // one warm-up round, three timed
  ASSERT_EQ(t.size(), 2u);
  for (const Timing& case_timing : t) {
    ASSERT_EQ(case_timing.seconds.size(), 3u);
    EXPECT_EQ(case_timing.median, median_of(case_timing.seconds));
    for (const double s : case_timing.seconds) EXPECT_GE(s, 0);
  }
}

TEST(BenchTiming, OneCaseRepeats) {
  int calls = 0;
  const Timing t = time_repeats([&] { ++calls; }, 5, 2);
  EXPECT_EQ(calls, 7);
  EXPECT_EQ(t.seconds.size(), 5u);
}

}  // namespace
}  // namespace phyxel::bench
