#include "engine/run/long_step.h"

#include <algorithm>
#include <chrono>

namespace phyxel {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int64_t advance_long_steps(Solver& solver, int64_t steps, int64_t substeps, double dt,
                           const std::function<bool()>& stop, double poll_seconds,
                           const std::function<void(double)>& on_rate) {
  const auto stopped = [&] { return stop && stop(); };
  int64_t chunk = 1;       // substeps per advance, from the rate measured so far
  double per_substep = 0;  // wall seconds per substep, 0 until measured
  int64_t timed_chunks = 0, timed_substeps = 0;
  double timed_seconds = 0;  // -1 once on_rate was called
  for (int64_t s = 0; s < steps; ++s) {
    // A step that takes well under a second goes in one advance, polled after it: the state at
    // its start need not be read back (a GPU's download).
    if (per_substep > 0 && per_substep * double(substeps) < 2.5 * poll_seconds) {
      const auto t0 = std::chrono::steady_clock::now();
      solver.advance(substeps, dt);
      solver.finish();
      per_substep = seconds_since(t0) / double(substeps);
      if (s + 1 < steps && stopped()) return s + 1;
      continue;
    }
    const PointState start = solver.read_state(false);
    for (int64_t done = 0; done < substeps;) {
      const int64_t n = std::min(chunk, substeps - done);
      const auto t0 = std::chrono::steady_clock::now();
      solver.advance(n, dt);
      solver.finish();
      done += n;
      const double took = seconds_since(t0);
      per_substep = std::max(took, 1e-12) / double(n);
      // The rate for on_rate: over the chunks after the first (which pays first-touch costs)
      // until they add up to poll_seconds.
      if (timed_chunks++ > 0 && timed_seconds >= 0) {
        timed_seconds += took;
        timed_substeps += n;
        if (timed_seconds >= poll_seconds) {
          if (on_rate) on_rate(double(timed_substeps) / timed_seconds);
          timed_seconds = -1;
        }
      }
      chunk = std::clamp<int64_t>(static_cast<int64_t>(poll_seconds / per_substep), 1, 4 * n);
      if (done < substeps && stopped()) {
        solver.set_state(start.displacement, start.velocity);
        return s;
      }
    }
    if (s + 1 < steps && stopped()) return s + 1;
  }
  return steps;
}

PolledToolSteps advance_long_tool_steps(Solver& solver, ToolTrack& tools, int64_t first_step,
                                        int64_t steps, int64_t substeps, double dt,
                                        const std::function<bool()>& stop, double poll_seconds) {
  const auto stopped = [&] { return stop && stop(); };
  PolledToolSteps out;
  Tools* facet = tools.empty() ? nullptr : &need(solver.tools(), solver, "simulate tools");
  int64_t chunk = 1;  // substeps per advance, from the rate measured so far
  for (int64_t s = 0; s < steps; ++s) {
    // The step's motions at once (fold reads them), handed to the solver a chunk at a time.
    const std::vector<ToolMotion> motions =
        tools.empty() ? std::vector<ToolMotion>{}
                      : tools.motions((first_step + s) * substeps, substeps, dt);
    const size_t nt = tools.size();
    std::vector<ToolContactSample> samples;
    for (int64_t done = 0; done < substeps;) {
      const int64_t n = std::min(chunk, substeps - done);
      const auto t0 = std::chrono::steady_clock::now();
      if (!tools.empty())
        facet->set_tool_motion(std::vector<ToolMotion>(motions.begin() + done * nt,
                                                       motions.begin() + (done + n) * nt));
      solver.advance(n, dt);
      if (!tools.empty()) {
        const std::vector<ToolContactSample> got = facet->tool_samples();
        samples.insert(samples.end(), got.begin(), got.end());
      }
      solver.finish();
      done += n;
      const double per_substep = std::max(seconds_since(t0), 1e-12) / double(n);
      chunk = std::clamp<int64_t>(static_cast<int64_t>(poll_seconds / per_substep), 1, 4 * n);
      if (done < substeps && stopped()) {
        out.within_step = done;
        return out;
      }
    }
    if (!tools.empty()) {
      const std::vector<ToolStepRecord> r = tools.fold(samples, 1, substeps);
      out.records.insert(out.records.end(), r.begin(), r.end());
    }
    out.steps = s + 1;
    if (s + 1 < steps && stopped()) return out;
  }
  return out;
}

}  // namespace phyxel
