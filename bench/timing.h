// The one timing loop of `phyxel bench`: warm-up calls, then timed repeats of one or several
// cases interleaved (A, B, A, B, ...: a machine that slows down slows every case alike), and
// the median of the repeats.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <vector>

namespace phyxel::bench {

double seconds_since(std::chrono::steady_clock::time_point t0);
// The median (the mean of the middle two for an even count); 0 when empty.
double median_of(std::vector<double> v);

struct Timing {
  std::vector<double> seconds;  // wall seconds of each timed repeat, in order
  double median = 0;            // of `seconds`
};

// Calls every case `warm_up` times untimed, then `repeats` times timed, the cases interleaved
// within each round; one Timing per case.
std::vector<Timing> time_interleaved(const std::vector<std::function<void()>>& cases,
                                     int64_t repeats, int64_t warm_up = 0);
// One case.
Timing time_repeats(const std::function<void()>& work, int64_t repeats, int64_t warm_up = 0);

}  // namespace phyxel::bench
