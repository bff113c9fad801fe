// The run loop's side of the tools: where each tool is at every substep (its path, or a pose
// source such as a haptic loop), and what each felt per step (from the solver's per-substep
// samples), with the statistics summary.json reports.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "engine/scene/scene.h"
#include "engine/solver/contact.h"
#include "engine/surgery/cut_feedback.h"

namespace phyxel {

// What one tool felt over a run.
struct ToolRunStats {
  std::string name;
  Vec3 last_force = Vec3::Zero();  // N, on the tool, mean over the last step's substeps
  double max_force = 0;            // N, the largest |force| of any step
  uint32_t contacts = 0;           // phyxels in contact at the last substep
  uint32_t max_contacts = 0;
  int64_t steps_in_contact = 0;
  // Scalpels: the largest cutting force of any substep (N; cut_force in
  // engine/solver/cutting.h: the edge or the point pressed into the tissue), and the substeps
  // at or above the threshold (cutting).
  bool cuts = false;
  double max_cut_force = 0;
  int64_t cutting_substeps = 0;
  // Scalpels, per step (cut_feedback.h): the largest force sent to the hand |F_x + f_c| (N),
  // the largest drag of the cut faces |f_c| (N) and the deepest the blade went (m).
  double max_feedback = 0;
  double max_friction = 0;
  double max_depth = 0;
  // Graspers (engine/solver/grasper.h): the phyxels the jaws hold at the last substep, the
  // most they held at a step's end, and the largest |force| of a step in which they held any
  // (N: the tissue pulling on the jaws).
  bool grasps = false;
  uint32_t held = 0;
  uint32_t max_held = 0;
  double max_pull_force = 0;
};

// One step's record of one tool (a row of tools.csv).
struct ToolStepRecord {
  ToolPose pose;              // at the end of the step
  Vec3 force = Vec3::Zero();  // N, on the tool, mean over the step's substeps
  uint32_t contacts = 0;      // at the step's last substep
  uint32_t held = 0;          // a grasper: phyxels its jaws hold at the step's last substep
  // Scalpels: the cutting force of eqs 21-26, its forces the mean over the step's substeps
  // (theta from the mean parts), the depth at its last substep. Zero for other tools.
  CutFeedback cut;
  // What the hand feels (the haptic loop's force): the contact reaction plus, for a scalpel,
  // the drag of the cut faces.
  Vec3 hand_force() const { return force + cut.friction; }
};

class ToolTrack {
 public:
  // pose_source(tool, t): the pose of a tool that is not path-driven ("control": "haptic") at
  // simulated time t; may be empty when no tool needs it (paths are used). `live_speeds`: per
  // tool, the top speed of a live one (m/s, simulated time; live_tool_speeds in
  // engine/scene/scene.h), needed when a tool is live.
  using PoseSource = std::function<ToolPose(size_t tool, double t)>;
  ToolTrack(const std::vector<ToolDesc>& tools, PoseSource pose_source,
            std::vector<double> live_speeds = {});

  bool empty() const { return tools_.empty(); }
  const ToolShape& shape(size_t tool) const { return tools_[tool].shape; }
  size_t size() const { return tools_.size(); }
  // Whether a tool follows a pose source instead of its path.
  bool live() const;

  // The motions of every tool over the substeps [first, first + count) of size dt (count x
  // tools, row-major by substep). Path tools: exactly their path at the substep boundaries.
  // Live tools: from the pose the last chunk ended at to the source's pose now, linearly, at
  // most their live speed in simulated time (a slow simulation's tool lags its device).
  std::vector<ToolMotion> motions(int64_t first, int64_t count, double dt);

  // Bounds of every tool over simulated time [from, to]: its pose now, its path's keys in
  // between and its pose at `to` (a live tool: its source's pose now).
  Bounds swept_bounds(double from, double to) const;

  // Folds an advance of `steps` steps of `substeps` substeps each (samples: steps x substeps
  // x tools) into per-step records; returns them (steps x tools) and updates the statistics.
  std::vector<ToolStepRecord> fold(const std::vector<ToolContactSample>& samples, int64_t steps,
                                   int64_t substeps);
  const std::vector<ToolRunStats>& stats() const { return stats_; }
  // The pose every tool ended the last chunk at.
  const std::vector<ToolPose>& poses() const { return last_; }
  // The pose every tool has after `substeps` (in [1, the chunk's]) substeps of the last chunk's
  // motions (a frame drawn inside the advance).
  std::vector<ToolPose> poses_after(int64_t substeps) const;
  // Continues a checkpointed run: the poses the tools ended its last chunk at and its
  // statistics (one each per tool; throws std::invalid_argument otherwise).
  void restore(const std::vector<ToolPose>& poses, const std::vector<ToolRunStats>& stats);
  // From the next advance on, `tool` leaves its path (or pose source): it moves from the pose
  // it ended the last chunk at to `pose` over `substeps` substeps, linearly (the axis by
  // slerp), then stays there (the Python module's set_tool_pose).
  void command(size_t tool, const ToolPose& pose, int64_t substeps);

 private:
  struct Command {
    bool active = false;
    ToolPose from, to;
    int64_t begin = -1;  // the substep the move starts at (-1: the next advance's first)
    int64_t substeps = 1;
  };
  ToolPose commanded_pose(size_t tool, int64_t substep) const;

  std::vector<ToolDesc> tools_;
  PoseSource source_;
  std::vector<double> live_speeds_;  // m/s, per tool
  std::vector<ToolPose> last_;       // end pose of the last chunk
  std::vector<ToolMotion> motions_;  // of the last chunk
  std::vector<ToolRunStats> stats_;
  std::vector<Command> commands_;  // per tool
};

}  // namespace phyxel
