// The viewer's simulation (render/viewer.h): the run loop of `phyxel run` and the Python module
// (engine/run/run_loop.h) advanced as many steps as a frame owes, with no end. The same phases,
// checks, loads, sleep, tearing and aspiration as `phyxel run`, so a scene moves in the window
// as it does there, step for step; a state that turns non-finite or runs away halts it.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "engine/run/run_loop.h"

namespace phyxel::render {

class ViewerSimulation {
 public:
  struct Hooks {
    // The pose of a haptic tool at simulated time t (RunOptions::tool_pose; may be empty).
    ToolTrack::PoseSource tool_pose;
    // After each step of a scene with tools: its end time and per tool its record.
    std::function<void(double t, const std::vector<ToolStepRecord>&)> on_tool_step;
    // After each aspiration (RunOptions::on_aspiration).
    std::function<void(const AspirationEvent&)> on_aspiration;
  };
  // scene, set and solver must outlive it. Throws as RunLoop's constructor does.
  ViewerSimulation(const Scene& scene, const PhyxelSet& set, Solver& solver, Hooks hooks);
  ViewerSimulation(const ViewerSimulation&) = delete;
  ViewerSimulation& operator=(const ViewerSimulation&) = delete;

  // Advances `steps` steps, fewer when the simulation halts. After each advance of the loop the
  // state is checked as the loop's checks do (non-finite, runaway) without waiting for the next
  // of them, so that no frame draws a state long lost; this changes no decision of the loop.
  // A rest (simulation.until_rest) does not end it: the viewer runs until its window closes.
  void advance(int64_t steps);
  int64_t step() const { return loop_.steps_done(); }
  // Empty while the state is finite and no phyxel outruns its material's wave speed (as the run
  // loop checks); else "halted: ..." with the step and phyxel, also said once on standard error.
  const std::string& halted() const { return halted_; }
  // What each tool felt in the last step (empty before the first step and without tools).
  const std::vector<ToolStepRecord>& felt() const { return felt_; }

 private:
  RunOptions run_options();
  void check_state();
  void halt(const char* what, int64_t step, long phyxel, double speed);

  Hooks hooks_;
  std::vector<ToolStepRecord> felt_;
  std::string halted_;
  RunLoop loop_;
};

}  // namespace phyxel::render
