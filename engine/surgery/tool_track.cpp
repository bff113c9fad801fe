#include "engine/surgery/tool_track.h"

#include "engine/solver/cutting.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace phyxel {

ToolTrack::ToolTrack(const std::vector<ToolDesc>& tools, PoseSource pose_source,
                     std::vector<double> live_speeds)
    : tools_(tools), source_(std::move(pose_source)), live_speeds_(std::move(live_speeds)) {
  for (const ToolDesc& t : tools_) {
    last_.push_back(pose_at(t.path, 0.0));
    stats_.push_back({t.name, Vec3::Zero(), 0, 0, 0, 0});
    stats_.back().cuts = t.blade.cuts();
    stats_.back().grasps = t.grasp.grasps();
  }
  commands_.resize(tools_.size());
  if (live() && !source_)
    throw std::invalid_argument("ToolTrack: a haptic tool needs a pose source");
  if (live() && live_speeds_.size() != tools_.size())
    throw std::invalid_argument("ToolTrack: a haptic tool needs its top speed");
  for (double v : live_speeds_)
    if (!(v > 0)) throw std::invalid_argument("ToolTrack: a live tool's top speed must be > 0");
}

bool ToolTrack::live() const {
  for (const ToolDesc& t : tools_)
    if (t.control == ToolDesc::Control::Haptic) return true;
  return false;
}

std::vector<ToolMotion> ToolTrack::motions(int64_t first, int64_t count, double dt) {
  const size_t nt = tools_.size();
  motions_.assign(static_cast<size_t>(count) * nt, {});
  for (size_t t = 0; t < nt; ++t) {
    const ToolDesc& tool = tools_[t];
    const bool live_tool = tool.control == ToolDesc::Control::Haptic && !commands_[t].active;
    if (commands_[t].active && commands_[t].begin < 0) {
      commands_[t].begin = first;
      commands_[t].from = last_[t];
    }
    const ToolPose start = last_[t];
    ToolPose target = live_tool ? source_(t, double(first + count) * dt) : ToolPose{};
    if (live_tool) {
      // A live tool moves at most its live speed in simulated time: when the physics runs
      // slower than real time, or stalls while the haptic loop runs on, a device moved at a
      // hand's speed would otherwise drive the tool through the tissue many times faster in
      // simulated time; the simulated tool lags.
      const Vec3 move = target.position - start.position;
      const double limit = live_speeds_[t] * double(count) * dt;
      if (move.norm() > limit) target.position = start.position + move * (limit / move.norm());
    }
    ToolPose from = start;
    for (int64_t k = 0; k < count; ++k) {
      ToolPose to;
      if (commands_[t].active) {
        to = commanded_pose(t, first + k + 1);
      } else if (live_tool) {
        const double s = double(k + 1) / double(count);
        to.position = start.position + s * (target.position - start.position);
        to.axis = slerp_axis(start.axis, target.axis, s);
      } else {
        to = tool.path_pose(double(first + k + 1) * dt);
      }
      // A haptic aspirator sucks all the time (the hand holds the pedal); a path one as its
      // suction says, at the substep's middle.
      const double middle = tool.cycle_time((double(first + k) + 0.5) * dt);
      const bool on = tool.suction.sucks() && (live_tool || tool.suction.on_at(middle));
      // A grasper's jaws as its grasp says, at the substep's middle, haptic or not.
      const bool closed = tool.grasp.closed_at(middle);
      motions_[static_cast<size_t>(k) * nt + t] = {from, to, on, closed};
      from = to;
    }
    last_[t] = from;
  }
  return motions_;
}

std::vector<ToolPose> ToolTrack::poses_after(int64_t substeps) const {
  const size_t nt = tools_.size();
  if (substeps < 1 || static_cast<size_t>(substeps) * nt > motions_.size())
    throw std::logic_error("ToolTrack::poses_after: " + std::to_string(substeps) +
                           " substeps, outside the last chunk's motions");
  std::vector<ToolPose> poses(nt);
  for (size_t t = 0; t < nt; ++t)
    poses[t] = motions_[static_cast<size_t>(substeps - 1) * nt + t].to;
  return poses;
}

Bounds ToolTrack::swept_bounds(double from, double to) const {
  Bounds b;
  for (size_t t = 0; t < tools_.size(); ++t) {
    const ToolDesc& tool = tools_[t];
    Bounds swept = tool_bounds(tool.shape, last_[t]);
    if (commands_[t].active) {
      swept.extend(tool_bounds(tool.shape, commands_[t].to));
    } else if (tool.control == ToolDesc::Control::Haptic) {
      swept.extend(tool_bounds(tool.shape, source_(t, to)));
    } else {
      // A repeating path's keys in the cycle's times of (from, to), all of them where it wraps.
      // Shifted as the cycles of `from` and `to` shift them (repeat_shift).
      const double a = tool.cycle_time(from), z = tool.cycle_time(to);
      const bool wraps = tool.repeat > 0 && (to - from >= tool.repeat || z < a);
      swept.extend(tool_bounds(tool.shape, tool.path_pose(to)));
      for (const double cycle : {tool.cycle_index(from), tool.cycle_index(to)})
        for (const ToolKey& k : tool.path)
          if (wraps || (k.t > a && k.t < z))
            swept.extend(tool_bounds(tool.shape, {k.position + cycle * tool.repeat_shift, k.axis}));
    }
    if (tool.suction.sucks()) swept.grow(tool.suction.reach);  // what its mouth pulls on
    if (tool.grasp.grasps()) swept.grow(tool.grasp.reach);     // what its jaws close on
    b.extend(swept);
  }
  return b;
}

std::vector<ToolStepRecord> ToolTrack::fold(const std::vector<ToolContactSample>& samples,
                                            int64_t steps, int64_t substeps) {
  const size_t nt = tools_.size();
  const size_t expected = static_cast<size_t>(steps * substeps) * nt;
  if (samples.size() != expected || motions_.size() != expected)
    throw std::logic_error("ToolTrack::fold: " + std::to_string(samples.size()) + " samples and " +
                           std::to_string(motions_.size()) + " motions for an advance of " +
                           std::to_string(expected));
  std::vector<ToolStepRecord> records(static_cast<size_t>(steps) * nt);
  for (int64_t s = 0; s < steps; ++s)
    for (size_t t = 0; t < nt; ++t) {
      ToolStepRecord& r = records[static_cast<size_t>(s) * nt + t];
      ToolRunStats& st = stats_[t];
      const Blade& blade = tools_[t].blade;
      for (int64_t k = 0; k < substeps; ++k) {
        const size_t at = static_cast<size_t>(s * substeps + k) * nt + t;
        r.force += samples[at].force;
        if (!blade.cuts()) continue;
        const CutFeedback f = cut_feedback(blade, tools_[t].friction, motions_[at], samples[at]);
        st.max_cut_force = std::max(st.max_cut_force, f.cut_force);
        if (f.cut_force >= blade.threshold) ++st.cutting_substeps;
        r.cut.cut_force += f.cut_force;
        r.cut.in_plane += f.in_plane;
        r.cut.normal += f.normal;
        r.cut.friction += f.friction;
        r.cut.depth = f.depth;
      }
      r.force /= double(substeps);
      if (blade.cuts()) {
        r.cut.cut_force /= double(substeps);
        r.cut.in_plane /= double(substeps);
        r.cut.normal /= double(substeps);
        r.cut.friction /= double(substeps);
        r.cut.theta = std::atan2(r.cut.in_plane, r.cut.normal);
        st.max_feedback = std::max(st.max_feedback, r.hand_force().norm());
        st.max_friction = std::max(st.max_friction, r.cut.friction.norm());
        st.max_depth = std::max(st.max_depth, r.cut.depth);
      }
      const size_t last = static_cast<size_t>(s * substeps + substeps - 1) * nt + t;
      r.contacts = samples[last].contacts;
      r.held = samples[last].held;
      st.held = r.held;
      st.max_held = std::max(st.max_held, r.held);
      if (r.held > 0) st.max_pull_force = std::max(st.max_pull_force, r.force.norm());
      r.pose = motions_[last].to;
      st.last_force = r.force;
      st.max_force = std::max(st.max_force, r.force.norm());
      st.contacts = r.contacts;
      st.max_contacts = std::max(st.max_contacts, r.contacts);
      if (r.contacts > 0) ++st.steps_in_contact;
    }
  return records;
}

void ToolTrack::restore(const std::vector<ToolPose>& poses,
                        const std::vector<ToolRunStats>& stats) {
  if (poses.size() != tools_.size() || stats.size() != tools_.size())
    throw std::invalid_argument("ToolTrack::restore: expected " + std::to_string(tools_.size()) +
                                " tools, got " + std::to_string(poses.size()));
  last_ = poses;
  stats_ = stats;
  for (size_t t = 0; t < tools_.size(); ++t) {
    stats_[t].cuts = tools_[t].blade.cuts();
    stats_[t].grasps = tools_[t].grasp.grasps();
  }
}

void ToolTrack::command(size_t tool, const ToolPose& pose, int64_t substeps) {
  if (tool >= tools_.size()) throw std::out_of_range("ToolTrack::command: no such tool");
  Command& c = commands_[tool];
  c.active = true;
  c.to = pose;
  c.to.axis.normalize();
  c.begin = -1;
  c.substeps = std::max<int64_t>(1, substeps);
}

ToolPose ToolTrack::commanded_pose(size_t tool, int64_t substep) const {
  const Command& c = commands_[tool];
  const double s = double(substep - c.begin) / double(c.substeps);
  if (s >= 1.0) return c.to;
  return {c.from.position + s * (c.to.position - c.from.position),
          slerp_axis(c.from.axis, c.to.axis, s)};
}

}  // namespace phyxel
