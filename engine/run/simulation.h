// The run shared by every solver: time-step plan (stable step, substeps), its options and
// result, and run_simulation, which drives the run loop (run_loop.h: stepping, rest and
// non-finite detection, output scheduling) to the end.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "engine/run/checkpoint.h"
#include "engine/solver/solver.h"
#include "engine/surgery/aspiration.h"
#include "engine/surgery/tool_track.h"

namespace phyxel {

struct TimeStepPlan {
  double dt_requested = 0;
  double dt_stable = 0;  // courant * min over phyxels of spacing / c_p
  double dt_used = 0;    // dt_requested / substeps
  int64_t substeps = 1;  // per requested step
  std::string reason;    // why substepping, empty when none
};

// The stable-step bound dt <= C s / c_p of DESIGN.md section 3 over every phyxel's material.
TimeStepPlan plan_time_step(const Scene& scene, const PhyxelSet& set);

struct RunOptions {
  int64_t steps = 0;              // requested steps (scene's unless overridden)
  std::filesystem::path out_dir;  // empty: write nothing
  std::function<void(int64_t step, int64_t total)> progress;  // may be empty
  // After each points file is whole on disk: its name, relative to out_dir (may be empty).
  std::function<void(const std::string& name)> on_points_written;
  bool pass_selection = true;  // false: --no-skip (every pass over every phyxel, no sleep)
  int64_t check_every = 0;     // steps between energy/finiteness checks; 0: automatic
  // Frames: on_frame(step, solver) every frame_every steps and at the end (0: never).
  int64_t frame_every = 0;
  std::function<void(int64_t step, Solver& solver)> on_frame;
  // Frames inside the advances (an on_frame that only draws from the GPU solver's buffers, as
  // Solver::advance_paused allows): with path tools, a frame between the tool chunks' lines is
  // drawn from inside the advance, after its step's work is submitted, instead of ending the
  // advance there (a drain of the GPU and a read-back of the tools). The tools' poses at its
  // step come first, by on_frame_tool_poses; the tool rows of its steps (on_tool_step) and
  // the cuts it draws (severed_since) are those up to the advance's start until the advance
  // ends. Ignored where the solver cannot pause (the CPU's), for live tools and in real time.
  bool frames_within_advance = false;
  std::function<void(const std::vector<ToolPose>& poses)> on_frame_tool_poses;
  // Tools (scene.tools): the pose of a haptic-controlled tool at simulated time t (required
  // when the scene has one); path tools follow their paths.
  ToolTrack::PoseSource tool_pose;
  // After every step of a scene with tools: the step, its end time and per tool its record.
  std::function<void(int64_t step, double t, const std::vector<ToolStepRecord>&)> on_tool_step;
  // Substeps per advance while tools move (the broad phase is built once per advance); 0 picks
  // by the body's phyxels (tool_chunk_substeps in run_schedule.h).
  int64_t tool_chunk_substeps = 0;
  // Pace simulated time to the wall clock (interactive and haptic runs): the loop advances the
  // steps the wall clock owes (at least one, at most a tool chunk) and sleeps while it is
  // ahead; RunResult says how far it fell behind.
  bool real_time = false;
  // Polled between advances: true stops the run after the current advance (signals, benches);
  // the last state and frame are then written as at the end. While it is set, an advance of a
  // scene without tools is cut to the steps that take about stop_poll_seconds of wall time at
  // the rate measured so far (such advances split exactly: the states are the same bit for
  // bit), so a stop is seen promptly even when a check interval takes minutes; tools already
  // advance at most a tool chunk at a time.
  std::function<bool()> stop_requested;
  double stop_poll_seconds = 0.1;
  // Steps of many substeps (engine/run/long_step.h): the substeps per wall second measured on
  // the first ones, for an estimate of the run's wall time (may be empty).
  std::function<void(double substeps_per_second)> on_substep_rate;
  // Checkpoints (engine/run/checkpoint.h): out_dir/checkpoint.phx every checkpoint_every steps
  // and at the end (0: never; needs out_dir). Advances end at those steps; the loop's checks
  // are unchanged. A run resumed from a checkpoint at step k is bit-identical to the run that
  // went on where that run also ended an advance at k (docs/checkpoint.md says when).
  int64_t checkpoint_every = 0;
  // Continue from this checkpoint (read by read_checkpoint; run_simulation verifies that it
  // belongs to the scene, set and solver and throws CheckpointError otherwise).
  const Checkpoint* resume = nullptr;
  std::filesystem::path resume_file;  // names it in errors (empty: out_dir/checkpoint.phx)
  // The scene's identity in checkpoints; unset: file_hash(scene.file) (a scene from text: the
  // hash of its text).
  std::optional<uint64_t> scene_hash;
  // Called before each checkpoint is written: outputs the caller buffers (tools.csv) must hold
  // every step up to it.
  std::function<void()> before_checkpoint;
  // After each aspiration (engine/surgery/aspiration.h) the run applied: what it removed and
  // exposed (the frame writer draws the new fracture surface).
  std::function<void(const AspirationEvent&)> on_aspiration;
};

struct RunResult {
  TimeStepPlan plan;
  int64_t steps_done = 0;
  double wall_seconds = 0;
  bool stopped_at_rest = false;
  bool stopped = false;  // RunOptions::stop_requested ended the run before its last step
  bool non_finite = false;
  int64_t non_finite_step = -1;  // first check at which a non-finite value was seen
  long non_finite_phyxel = -1;
  // The tool that had the most phyxels in contact in the steps since the check before the
  // non-finite one (index into scene.tools; -1 where no tool touched the tissue then), and
  // that many phyxels: a tool drove the tissue past what the step holds, most likely.
  int non_finite_tool = -1;
  uint32_t non_finite_tool_contacts = 0;
  // A finite but runaway state: some phyxel faster than its material's p-wave speed.
  bool unstable = false;
  int64_t unstable_step = -1;
  long unstable_phyxel = -1;
  double unstable_speed = 0, unstable_wave_speed = 0;
  // The tool nearest the runaway phyxel where one is within two support radii of it (index
  // into scene.tools, else -1) and the phyxel's distance from its surface (m, negative inside),
  // at the step it was found: a tool drove the tissue there past what the step holds.
  int unstable_tool = -1;
  double unstable_tool_distance = 0;
  int64_t sleeps = 0, wakes = 0;  // object sleep and wake events
  int64_t load_changes = 0;
  Energies energies;
  double max_displacement = 0;
  std::vector<std::string> outputs;  // files written, relative to out_dir
  std::vector<ToolRunStats> tools;   // per scene tool
  double simulated_time = 0;         // s
  double real_time_factor = 0;       // simulated seconds per wall second
  double max_lag = 0;                // real_time runs: the most wall time was ahead of it, s
  // Where the wall time went, s: advancing the solver (contact broad phase included), the
  // checks (state read back, runaway, energies, sleep), the tool-step callbacks (haptics,
  // tools.csv), sleeping to keep pace with the clock, and outputs and frames.
  struct WallSplit {
    double advance = 0, checks = 0, callbacks = 0, pacing = 0, outputs = 0;
    AspirationTimes aspiration;  // the aspirations' part of callbacks
  } split;
  int64_t resumed_from = -1;  // the checkpoint's step, or -1
  // Suction tools in a scene that can tear: what the aspirations took (aspiration.h).
  bool aspirating = false;
  AspirationTotals aspiration;
};

// RunLoop's steps to the end, then its finish().
RunResult run_simulation(const Scene& scene, const PhyxelSet& set, Solver& solver,
                         const RunOptions& options);

// Advances `solver` by `steps` steps of `substeps` substeps of dt from step `first`, the tools
// moving as `tools` says (ToolTrack::motions for the advance, then ToolTrack::fold of the
// solver's samples). Returns the per-step records (steps x tools; empty without tools). The run
// loop and the viewer step tools this way.
// With `pauses` (substeps into the advance), Solver::advance_paused calls at(k) at each.
// `ready` runs once the tools' motions are set, before the advance (tools.poses(): where the
// tools end it).
std::vector<ToolStepRecord> advance_with_tools(Solver& solver, ToolTrack& tools, int64_t first,
                                               int64_t steps, int64_t substeps, double dt,
                                               const std::vector<int64_t>& pauses = {},
                                               const std::function<void(int64_t)>& at = {},
                                               const std::function<void()>& ready = {});

// A finite state running away: the first phyxel faster than its material's p-wave speed
// (which no elastic tissue is: it would mean a strain above one per step), or phyxel -1.
struct Runaway {
  long phyxel = -1;
  double speed = 0, wave_speed = 0;
};
Runaway find_runaway(const PhyxelSet& set, const std::vector<Vec3>& velocity);

// The passes the run will record and why, one per line (phyxel run --explain).
std::string explain_passes(const Scene& scene, const PhyxelSet& set, Solver& solver,
                           const RunOptions& options);

}  // namespace phyxel
