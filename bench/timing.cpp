#include "bench/timing.h"

#include <algorithm>

namespace phyxel::bench {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double median_of(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::vector<Timing> time_interleaved(const std::vector<std::function<void()>>& cases,
                                     int64_t repeats, int64_t warm_up) {
  for (int64_t w = 0; w < warm_up; ++w)
    for (const auto& work : cases) work();
  std::vector<Timing> out(cases.size());
  for (int64_t r = 0; r < repeats; ++r) {
    for (size_t c = 0; c < cases.size(); ++c) {
      const auto t0 = std::chrono::steady_clock::now();
      cases[c]();
      out[c].seconds.push_back(seconds_since(t0));
    }
  }
  for (Timing& t : out) t.median = median_of(t.seconds);
  return out;
}

Timing time_repeats(const std::function<void()>& work, int64_t repeats, int64_t warm_up) {
  return time_interleaved({work}, repeats, warm_up).front();
}

}  // namespace phyxel::bench
