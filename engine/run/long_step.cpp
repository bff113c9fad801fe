#include "engine/run/long_step.h"

#include <algorithm>
#include <chrono>

namespace phyxel {

int64_t advance_long_steps(Solver& solver, int64_t steps, int64_t substeps, double dt,
                           const std::function<bool()>& stop, double poll_seconds) {
  int64_t chunk = 1;  // substeps per advance, from the rate measured so far
  for (int64_t s = 0; s < steps; ++s) {
    const PointState start = solver.read_state(false);
    for (int64_t done = 0; done < substeps;) {
      const int64_t n = std::min(chunk, substeps - done);
      const auto t0 = std::chrono::steady_clock::now();
      solver.advance(n, dt);
      solver.finish();
      done += n;
      const double took =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const double fit = poll_seconds * double(n) / std::max(took, 1e-9);
      chunk = std::clamp<int64_t>(static_cast<int64_t>(fit), 1, 4 * n);
      if (done < substeps && stop && stop()) {
        solver.set_state(start.displacement, start.velocity);
        return s;
      }
    }
  }
  return steps;
}

}  // namespace phyxel
