// The run loop as a class: step() is one advance to the next step at which something has to
// be looked at, in named phases. run_simulation (simulation.h) drives it to the end (`phyxel
// run`); the Python module (python/) drives it a number of steps at a time. One loop, so the
// two give the same numbers.
#pragma once

#include <chrono>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "engine/run/simulation.h"

namespace phyxel {

class RunLoop {
 public:
  // Checks the scene against the solver's abilities (throws std::runtime_error naming the
  // scene file), sets the solver up and, with options.resume, continues from the checkpoint
  // (throws CheckpointError). scene, set and solver must outlive the loop.
  RunLoop(const Scene& scene, const PhyxelSet& set, Solver& solver, const RunOptions& options);

  // Whether step() has anything left: before the total, not at rest, not stopped, not failed.
  bool running() const;
  // One advance: next stop, advance, surgery events, pacing, loads, checkpoint, checks,
  // outputs (in this order; see run_loop.cpp). It ends by step `until` (> steps_done()) too:
  // an interactive caller (render/viewer_simulation.h) advances what its frame owes; such a
  // stop, like a frame's, changes no decision of the loop.
  void step(int64_t until = std::numeric_limits<int64_t>::max());
  // The end of the run: the last checkpoint and points file (unless the state failed), the
  // energies and the result. Once, after running() turned false.
  RunResult finish();

  // For a caller that advances a few steps at a time (python/): the run now ends at `total`
  // (>= steps_done()), as a run of `total` steps resumed here would; a stop or a rest that
  // ended the last stretch no longer holds.
  void extend(int64_t total);
  // Between the loop's checks (phyxel view, each frame): finite and no phyxel faster than its
  // wave speed, else the result says so and the loop ends; decides nothing else (rest, sleep).
  bool check_stability();
  // The result so far (steps, tools, aspiration, energies, largest displacement), writing
  // nothing.
  RunResult snapshot();
  // The checkpoint of the loop's state now (engine/run/checkpoint.h).
  Checkpoint checkpoint();

  int64_t steps_done() const { return step_; }
  int64_t total() const { return total_; }
  const RunResult& result() const { return result_; }
  ToolTrack& tools() { return tools_; }
  double step_time() const { return step_time_; }

 private:
  void resume(const Checkpoint& c);  // phase "resume"
  int64_t next_stop() const;         // phase "next stop"
  bool polled_within_steps() const;  // the next advance polls between substeps
  std::vector<ToolStepRecord> advance(int64_t& next);
  // Frames inside the advance to `next` (RunOptions::frames_within_advance): their substeps.
  std::vector<int64_t> frame_pauses(int64_t next) const;
  void frame_at_pause(int64_t substep);
  void surgery_events(int64_t next, const std::vector<ToolStepRecord>& records);
  bool aspirates_at(int64_t next) const;  // whether the aspirator acts after the advance to next
  void tool_rows(int64_t next, const std::vector<ToolStepRecord>& records);
  void pacing(int64_t next);
  void switch_loads(int64_t previous);
  bool check();  // false: the state failed (non-finite or running away); the loop ends
  bool check_finite();
  bool check_runaway(const PointState& state);
  void decide_rest_and_sleep(const std::vector<ObjectMotion>& motion);
  void outputs(bool regular);
  void write_points(int64_t step);
  void write_checkpoint_now();
  void lap(double& into);

  const Scene& scene_;
  const PhyxelSet& set_;
  Solver& solver_;
  RunOptions options_;
  RunResult result_;
  int64_t total_ = 0;
  int64_t every_ = 0;  // scene.output.every
  double step_time_ = 0;
  bool sleeping_ = false;
  std::vector<int64_t> events_;  // load switch steps
  int64_t check_ = 1;            // check interval
  ToolTrack tools_;
  // Per tool, the most phyxels in contact at a step since the last check (RunResult's
  // non_finite_tool).
  std::vector<uint32_t> contacts_since_check_;
  Aspirator aspirator_;
  int64_t tool_chunk_ = 0;      // steps per advance while tools move
  bool frames_within_ = false;  // RunOptions::frames_within_advance, where it holds
  // Each sleeping object's displacement when it went to sleep (its u does not change asleep).
  std::vector<Vec3> last_u_;
  double slowest_wave_ = 0;  // find_runaway's bound
  int64_t below_since_ = -1;
  std::vector<int64_t> object_below_since_;
  std::vector<uint8_t> awake_;
  std::optional<uint64_t> scene_hash_;
  // Advances without tools split exactly, so they can be cut short to see a stop promptly.
  bool polled_ = false;
  bool long_steps_ = false;  // may be polled between substeps too (polled_within_steps)
  // With tools or tearing, polled between substeps without going back (long_step.h); a stop
  // inside a step ends the run there, writing nothing of that state.
  bool long_tool_steps_ = false;
  bool within_step_ = false;
  double step_seconds_ = -1;  // wall seconds per step of the last advance; -1 before the first
  int64_t poll_steps_ = 1;    // steps per advance while polled, from the measured rate
  int64_t step_ = 0;
  size_t next_event_ = 0;
  int64_t checkpointed_ = -1;  // the step of the last checkpoint
  std::chrono::steady_clock::time_point start_, paced_from_, mark_;
};

}  // namespace phyxel
