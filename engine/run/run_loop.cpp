#include "engine/run/run_loop.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <thread>

#include "engine/run/long_step.h"
#include "engine/run/run_schedule.h"
#include "engine/run/vtp_writer.h"
#include "engine/solver/check_prefetch.h"

namespace phyxel {
namespace {

std::string points_name(int64_t step) {
  char name[64];
  std::snprintf(name, sizeof name, "points_%06lld.vtp", static_cast<long long>(step));
  return name;
}

double max_norm(const std::vector<Vec3>& u) {
  double m = 0;
  for (const Vec3& x : u) m = std::max(m, x.norm());
  return m;
}

int64_t next_multiple(int64_t step, int64_t n) {
  return (step / n + 1) * n;
}

// Sleeps or wakes an object where the solver selects passes (without, every object is awake).
void set_object_awake(Solver& solver, uint32_t object, bool awake) {
  if (PassSelection* passes = solver.pass_selection()) passes->set_object_awake(object, awake);
}

// A sleeping object wakes when a tool comes near it: some phyxel of it (at its displacement
// when it went to sleep, which has not changed since) within the tools' swept bounds over the
// next advance, grown by the object's spacing.
void wake_touched_objects(const PhyxelSet& set, const Bounds& bounds,
                          const std::vector<Vec3>& last_u, std::vector<uint8_t>& awake,
                          std::vector<int64_t>& below_since, Solver& solver, RunResult& result) {
  for (size_t o = 0; o < set.objects.size(); ++o) {
    if (awake[o]) continue;
    const ObjectRange& obj = set.objects[o];
    Bounds near = bounds;
    near.grow(obj.spacing);
    for (uint32_t i = obj.first; i < obj.first + obj.count; ++i) {
      const Vec3 x = set.rest[i] + last_u[i];
      if ((x.array() >= near.min.array()).all() && (x.array() <= near.max.array()).all()) {
        awake[o] = 1;
        below_since[o] = -1;
        set_object_awake(solver, static_cast<uint32_t>(o), true);
        ++result.wakes;
        break;
      }
    }
  }
}

// Real time: the steps the wall clock owes the simulation (at least one).
int64_t steps_owed(std::chrono::steady_clock::time_point start, int64_t step, double step_time) {
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return std::max<int64_t>(1, static_cast<int64_t>(std::floor(wall / step_time)) - step);
}

// Real-time pacing: sleep while the simulation is ahead of the wall clock; note the lag when
// it is behind.
void pace(std::chrono::steady_clock::time_point start, double simulated, RunResult& result) {
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (simulated > wall)
    std::this_thread::sleep_for(std::chrono::duration<double>(simulated - wall));
  else
    result.max_lag = std::max(result.max_lag, wall - simulated);
}

// The steps that take about `seconds` of wall time at the rate of the advance of `steps` steps
// that began at `since`: at least one, at most four times `previous` (a first short advance
// can be unrepresentatively fast).
int64_t steps_within(double seconds, int64_t steps, std::chrono::steady_clock::time_point since,
                     int64_t previous) {
  const double took =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
  const double fit = seconds * double(steps) / std::max(took, 1e-9);
  return std::clamp<int64_t>(static_cast<int64_t>(std::min(fit, 4.0 * double(previous))), 1,
                             std::max<int64_t>(1, 4 * previous));
}

// The checkpoint of the run loop's state after `step` steps.
Checkpoint make_checkpoint(const Scene& scene, const PhyxelSet& set, Solver& solver,
                           uint64_t scene_hash, int64_t step, const RunResult& result) {
  Checkpoint c;
  c.scene_hash = scene_hash;
  c.set_hash = phyxel_set_hash(set);
  c.device = solver.device();
  c.solver = solver_identity(c.device);
  c.step = step;
  c.dt_requested = scene.simulation.dt;
  c.time = double(step) * c.dt_requested;
  c.substeps = result.plan.substeps;
  PointState state = solver.read_state(false);
  c.displacement = std::move(state.displacement);
  c.velocity = std::move(state.velocity);
  c.sleeps = result.sleeps;
  c.wakes = result.wakes;
  c.load_changes = result.load_changes;
  c.flags = set.flags;
  return c;
}

// The abilities the scene needs that the solver lacks: a std::runtime_error naming the file.
void require_abilities(const Scene& scene, Solver& solver, bool tearing, bool load_changes,
                       bool aspirating, bool tools) {
  const std::string file = scene.file.string();
  if (tearing && !solver.tearing())
    throw std::runtime_error(file + ": a material has tear_stress, which " + solver.device() +
                             " cannot evaluate; use --device cpu");
  if (load_changes && !solver.load_changes())
    throw std::runtime_error(file +
                             ": loads with from/until switch during the run, "
                             "which " +
                             solver.device() + " cannot do; use --device cpu");
  if (aspirating && !solver.removal())
    throw std::runtime_error(file + ": a suction tool aspirates tissue, which " + solver.device() +
                             " cannot remove; use --device cpu or gpu");
  if (tools && !solver.tools())
    throw std::runtime_error(file + ": the scene has tools, which " + solver.device() +
                             " cannot simulate; use --device cpu");
}

}  // namespace

RunLoop::RunLoop(const Scene& scene, const PhyxelSet& set, Solver& solver,
                 const RunOptions& options)
    : scene_(scene),
      set_(set),
      solver_(solver),
      options_(options),
      tools_(scene.tools, options.tool_pose, live_tool_speeds(scene)),
      aspirator_(scene, set) {
  result_.plan = plan_time_step(scene, set);
  total_ = options.steps;
  every_ = scene.output.every;
  step_time_ = result_.plan.dt_requested;
  PassSelection* passes = solver.pass_selection();
  const bool select = options.pass_selection && passes;
  if (passes) passes->set_pass_selection(select);
  // Tearing: the largest principal stress of every stressed phyxel, and the overstressed
  // pairs severed, each substep.
  const bool tearing = scene.tearing_possible();
  events_ = load_event_steps(set, step_time_, total_);
  require_abilities(scene, solver, tearing, !events_.empty(), aspirator_.active(), !tools_.empty());
  if (PrincipalStress* principal = solver.principal_stress())
    principal->set_principal_stress(tearing);
  if (Tearing* tear = solver.tearing()) tear->set_tearing(tearing);
  sleeping_ = select && scene.simulation.sleep.enabled;
  tool_chunk_ = tool_chunk_steps(scene, options, set.size(), result_.plan.substeps, step_time_);
  check_ = check_interval(scene, options, sleeping_, tool_chunk_);
  contacts_since_check_.assign(tools_.size(), 0u);
  if (!tools_.empty()) solver.tools()->set_tools(contact_tools(scene.tools));  // required above
  last_u_.assign(set.size(), Vec3::Zero());
  slowest_wave_ = std::numeric_limits<double>::infinity();
  for (const Material& m : set.materials) slowest_wave_ = std::min(slowest_wave_, p_wave_speed(m));
  object_below_since_.assign(set.objects.size(), -1);
  awake_.assign(set.objects.size(), 1);
  if (options.checkpoint_every > 0 && options.out_dir.empty())
    throw std::runtime_error("checkpoints need an output folder");
  if (options.scene_hash)
    scene_hash_ = *options.scene_hash;
  else if (options.checkpoint_every > 0 || options.resume)
    scene_hash_ = scene.file.empty() ? 0 : file_hash(scene.file);
  polled_ = options.stop_requested && tools_.empty();
  // Steps of many substeps, or slow ones, are polled between substeps too (long_step.h).
  long_steps_ = polled_ && !tearing && result_.plan.substeps > 1;
  long_tool_steps_ =
      options.stop_requested && (tearing || !tools_.empty()) && result_.plan.substeps > 1;
  frames_within_ = options.frames_within_advance && options.on_frame && options.frame_every > 0 &&
                   tool_chunk_ > 0 && !tools_.live() && !options.real_time &&
                   solver.pauses_within_advance();
  if (options.resume) {
    resume(*options.resume);
    checkpointed_ = step_;
  }
  start_ = std::chrono::steady_clock::now();
  // Real-time pacing counts simulated time from step 0: a resumed run's clock starts where the
  // checkpoint's simulated time was.
  paced_from_ = start_ - std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                             std::chrono::duration<double>(double(step_) * step_time_));
}

void RunLoop::resume(const Checkpoint& c) {
  const std::string name =
      (options_.resume_file.empty() ? options_.out_dir / kCheckpointFile : options_.resume_file)
          .string();
  check_checkpoint_matches(c, name, *scene_hash_, set_, solver_.device());
  if (c.dt_requested != step_time_ || c.substeps != result_.plan.substeps ||
      c.check_every != check_)
    throw CheckpointError(name +
                          ": written with another time step, substep count or check "
                          "interval (--check-every) than this run's");
  if (c.step > total_)
    throw CheckpointError(name + ": at step " + std::to_string(c.step) + ", past the " +
                          std::to_string(total_) + " steps this run is asked for");
  if (c.loads_applied > static_cast<int64_t>(events_.size()) ||
      (c.loads_applied > 0 && events_[c.loads_applied - 1] > c.step) ||
      c.tool_stats.size() != tools_.size() ||
      (!tools_.empty() && c.last_check_u.size() != set_.size()))
    throw CheckpointError(name + ": its load schedule or tools differ from the scene's");
  step_ = c.step;
  result_.resumed_from = c.step;
  result_.sleeps = c.sleeps;
  result_.wakes = c.wakes;
  result_.load_changes = c.load_changes;
  next_event_ = static_cast<size_t>(c.loads_applied);
  if (next_event_ > 0)
    need(solver_.load_changes(), solver_, "switch loads")
        .set_external_forces(external_forces_at(set_, events_[next_event_ - 1] * step_time_));
  for (size_t o = 0; o < set_.objects.size(); ++o) {
    awake_[o] = c.awake[o];
    object_below_since_[o] = c.object_below_since[o];
    if (!awake_[o]) set_object_awake(solver_, static_cast<uint32_t>(o), false);
  }
  below_since_ = c.rest_below_since;
  if (!tools_.empty()) {
    last_u_ = c.last_check_u;
    tools_.restore(c.tool_poses, c.tool_stats);
  }
  if (!c.severed.empty())  // the cuts, before the state's forces
    need(solver_.cutting(), solver_, "sever pairs").sever_pairs(c.severed);
  try {
    if (!c.blade_sides.empty())  // the sides the blades keep (after set_tools)
      need(solver_.cutting(), solver_, "keep a blade's sides").restore_blade_sides(c.blade_sides);
    if (std::count(c.blades_cutting.begin(), c.blades_cutting.end(), 1) > 0)  // mid-cut blades
      need(solver_.cutting(), solver_, "keep a blade cutting")
          .restore_blades_cutting(c.blades_cutting);
    aspirator_.restore(c.aspiration, solver_, c.severed);  // the aspirated phyxels
    if (!c.band.phyxel.empty() || !c.band.quads.empty())   // after the cuts and removals
      need(solver_.cutting(), solver_, "restore the SCNI band").restore_cut_band(c.band);
    if (has_grasper(scene_))
      need(solver_.tools(), solver_, "restore a grasper's grip").restore_grips(c.grips);
  } catch (const std::invalid_argument& e) {
    throw CheckpointError(name + ": " + e.what());
  }
  solver_.set_state(c.displacement, c.velocity);  // last: the forces for this u and state
  // A load switching exactly at the step a shorter run ended on: it never applied it.
  if (next_event_ < events_.size() && events_[next_event_] == step_) switch_loads(step_ - 1);
  // A run that had come to rest stays finished (its last check said so).
  const UntilRest& rest = scene_.simulation.until_rest;
  if (rest.enabled && below_since_ >= 0 && step_ - below_since_ >= rest.for_steps)
    result_.stopped_at_rest = true;
  // summary.json lists the whole run's outputs: the snapshots written before the checkpoint.
  for (int64_t s = every_; every_ > 0 && !options_.out_dir.empty() && s <= step_ && s < total_;
       s += every_)
    result_.outputs.push_back(points_name(s));
}

bool RunLoop::running() const {
  return step_ < total_ && !result_.stopped_at_rest && !result_.stopped && !result_.non_finite &&
         !result_.unstable;
}

void RunLoop::step(int64_t until) {
  int64_t next = std::min(next_stop(), std::max(until, step_ + 1));
  const std::vector<ToolStepRecord> records = advance(next);
  if (within_step_) {  // stopped inside a step: the rows of the whole steps, then the end
    tool_rows(next, records);
    step_ = next;
    result_.stopped = true;
    return;
  }
  surgery_events(next, records);
  pacing(next);
  const int64_t previous = step_;
  step_ = next;
  if (options_.progress) options_.progress(step_, total_);
  if (next_event_ < events_.size() && events_[next_event_] == step_) switch_loads(previous);
  // Checkpoints hold the state a run that goes on has at this step: after the check where the
  // loop checks, before the end's extra check (its sleep and rest decisions) where it does
  // not. Adding checkpoints thus changes no decision of the loop.
  const int64_t checkpoint_every = options_.checkpoint_every;
  const bool regular = step_ % check_ == 0;
  if (checkpoint_every > 0 && (step_ % checkpoint_every == 0 || step_ == total_) && !regular &&
      solver_.first_non_finite() < 0) {
    write_checkpoint_now();
    checkpointed_ = step_;
  }
  if ((regular || step_ == total_) && !check()) return;
  lap(result_.split.checks);
  outputs(regular);
}

// Whether the next advance polls the stop between substeps: steps of many substeps, and
// steps measured (or, before the first, assumed) to take longer than a poll. Chunked advances
// give the same states bit for bit (long_step.h), so timing decides only where a stop lands.
bool RunLoop::polled_within_steps() const {
  if (!long_steps_ && !long_tool_steps_) return false;
  return result_.plan.substeps >= kLongStepSubsteps || step_seconds_ < 0 ||
         step_seconds_ >= 2.5 * options_.stop_poll_seconds;
}

// Advance to the next step at which something has to be looked at.
int64_t RunLoop::next_stop() const {
  int64_t next = std::min(total_, next_multiple(step_, check_));
  if (every_ > 0) next = std::min(next, next_multiple(step_, every_));
  // Frames drawn inside the advance do not end it (frame_pauses).
  if (options_.frame_every > 0 && !(frames_within_ && !polled_within_steps()))
    next = std::min(next, next_multiple(step_, options_.frame_every));
  if (next_event_ < events_.size()) next = std::min(next, events_[next_event_]);
  // Tool chunks on a fixed grid from step 0, whatever else splits an advance (frames,
  // outputs, checks, real-time pacing): the aspirator acts only at its lines, so what is
  // aspirated does not depend on how often frames are drawn.
  if (tool_chunk_ > 0) next = std::min(next, next_multiple(step_, tool_chunk_));
  if (options_.checkpoint_every > 0)
    next = std::min(next, next_multiple(step_, options_.checkpoint_every));
  // Real time: advance what the wall clock owes (at least a step, at most a tool chunk), so
  // a live tool's pose reaches the physics every few milliseconds of wall time.
  if (options_.real_time) next = std::min(next, step_ + steps_owed(paced_from_, step_, step_time_));
  // A stop can be asked for: advance no more than about stop_poll_seconds of wall time.
  if (polled_) next = std::min(next, step_ + poll_steps_);
  return next;
}

std::vector<ToolStepRecord> RunLoop::advance(int64_t& next) {
  if (!tools_.empty())  // sleeping objects the tools are about to reach wake first
    wake_touched_objects(set_, tools_.swept_bounds(step_ * step_time_, next * step_time_), last_u_,
                         awake_, object_below_since_, solver_, result_);
  mark_ = std::chrono::steady_clock::now();
  const auto advance_start = mark_;
  std::vector<ToolStepRecord> records;
  const bool within = polled_within_steps();
  if (within && long_steps_)  // a stop mid-step ends the run at the last whole step
    next = step_ + advance_long_steps(solver_, next - step_, result_.plan.substeps,
                                      result_.plan.dt_used, options_.stop_requested,
                                      options_.stop_poll_seconds, options_.on_substep_rate);
  else if (within && long_tool_steps_) {
    PolledToolSteps r = advance_long_tool_steps(
        solver_, tools_, step_, next - step_, result_.plan.substeps, result_.plan.dt_used,
        options_.stop_requested, options_.stop_poll_seconds);
    next = step_ + r.steps;
    records = std::move(r.records);
    within_step_ = r.within_step > 0;
  } else {
    // The checks of `next` (step()) inside the advance, unless something changes the state
    // between (the solver then reads again).
    if (next % check_ == 0 || next == total_)
      if (auto* checks = dynamic_cast<CheckPrefetch*>(&solver_)) checks->prefetch_checks();
    records = advance_with_tools(
        solver_, tools_, step_, next - step_, result_.plan.substeps, result_.plan.dt_used,
        frame_pauses(next), [this](int64_t substep) { frame_at_pause(substep); },
        [this, next] {  // the aspiration's read at `next` inside the advance (surgery_events)
          if (aspirates_at(next))
            aspirator_.before_advance(solver_, tools_.poses(), double(next) * step_time_);
        });
  }
  for (size_t r = 0; r < records.size(); ++r) {
    uint32_t& most = contacts_since_check_[r % tools_.size()];
    most = std::max(most, records[r].contacts);
  }
  if (polled_)
    poll_steps_ =
        steps_within(options_.stop_poll_seconds, next - step_, advance_start, poll_steps_);
  if (next > step_)
    step_seconds_ =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - advance_start).count() /
        double(next - step_);
  lap(result_.split.advance);
  return records;
}

std::vector<int64_t> RunLoop::frame_pauses(int64_t next) const {
  std::vector<int64_t> pauses;
  if (!frames_within_) return pauses;
  for (int64_t s = next_multiple(step_, options_.frame_every); s < next; s += options_.frame_every)
    pauses.push_back((s - step_) * result_.plan.substeps);
  return pauses;
}

// A frame inside the advance: the tools where they are at its step, then the frame.
void RunLoop::frame_at_pause(int64_t substep) {
  if (options_.on_frame_tool_poses) options_.on_frame_tool_poses(tools_.poses_after(substep));
  options_.on_frame(step_ + substep / result_.plan.substeps, solver_);
}

// On the tool chunks' grid; at the end too unless the run keeps checkpoints (a run that can be
// continued must not aspirate off the grid: the continued run would differ).
bool RunLoop::aspirates_at(int64_t next) const {
  const bool end = next == total_ && options_.checkpoint_every == 0;
  return aspirator_.active() && tool_chunk_ > 0 && (next % tool_chunk_ == 0 || end);
}

// The tools' records to the caller, then the paper's hybrid tearing at the aspirators' mouths
// at the end of each tool chunk.
void RunLoop::surgery_events(int64_t next, const std::vector<ToolStepRecord>& records) {
  tool_rows(next, records);
  // The events' rest-space fields only for a listener (map_fracture_to_rest: outcomes alike).
  if (aspirates_at(next))
    for (const AspirationEvent& e : aspirator_.after_advance(
             solver_, tools_.poses(), double(next) * step_time_, bool(options_.on_aspiration)))
      if (options_.on_aspiration) options_.on_aspiration(e);
  lap(result_.split.callbacks);
}

void RunLoop::tool_rows(int64_t next, const std::vector<ToolStepRecord>& records) {
  for (int64_t s = step_; options_.on_tool_step && !tools_.empty() && s < next; ++s)
    options_.on_tool_step(
        s + 1, double(s + 1) * step_time_,
        std::vector<ToolStepRecord>(records.begin() + (s - step_) * tools_.size(),
                                    records.begin() + (s - step_ + 1) * tools_.size()));
}

void RunLoop::pacing(int64_t next) {
  if (options_.real_time) pace(paced_from_, double(next) * step_time_, result_);
  lap(result_.split.pacing);
}

// Loads switch at step_ (after `previous`): apply the new ones and wake every object whose
// loads changed.
void RunLoop::switch_loads(int64_t previous) {
  ++next_event_;
  ++result_.load_changes;
  need(solver_.load_changes(), solver_, "switch loads")
      .set_external_forces(external_forces_at(set_, step_ * step_time_));
  for (const LoadSpread& load : set_.loads) {
    if (load.active_at(previous * step_time_) == load.active_at(step_ * step_time_)) continue;
    object_below_since_[load.object] = -1;
    if (!awake_[load.object]) {
      awake_[load.object] = 1;
      set_object_awake(solver_, load.object, true);
      ++result_.wakes;
    }
  }
}

// Points files, frames and the checkpoint of a checked step; a stop asked for ends the run.
void RunLoop::outputs(bool regular) {
  result_.stopped = step_ < total_ && !result_.stopped_at_rest && options_.stop_requested &&
                    options_.stop_requested();
  const bool last = step_ == total_ || result_.stopped_at_rest || result_.stopped;
  if (every_ > 0 && step_ % every_ == 0 && !last) write_points(step_);
  if (options_.on_frame && options_.frame_every > 0 && (step_ % options_.frame_every == 0 || last))
    options_.on_frame(step_, solver_);
  if (options_.checkpoint_every > 0 && step_ % options_.checkpoint_every == 0 && regular) {
    write_checkpoint_now();
    checkpointed_ = step_;
  }
  lap(result_.split.outputs);
}

void RunLoop::write_points(int64_t step) {
  if (options_.out_dir.empty()) return;
  PointState state = solver_.read_state(true);
  // The solvers always report a contact flag per phyxel (all 0 without tools); the .vtp
  // files carry the `contact` array for scenes with tools only.
  if (scene_.tools.empty()) state.contact.clear();
  const std::string name = points_name(step);
  write_points_vtp(options_.out_dir / name, set_, state, scene_.output.binary);
  result_.outputs.push_back(name);
  if (options_.on_points_written) options_.on_points_written(name);
}

Checkpoint RunLoop::checkpoint() {
  if (!scene_hash_) scene_hash_ = scene_.file.empty() ? 0 : file_hash(scene_.file);
  Checkpoint c = make_checkpoint(scene_, set_, solver_, *scene_hash_, step_, result_);
  c.check_every = check_;
  c.checkpoint_every = options_.checkpoint_every;
  c.total = total_;
  c.awake = awake_;
  c.object_below_since = object_below_since_;
  c.loads_applied = static_cast<int64_t>(next_event_);
  c.rest_below_since = below_since_;
  if (!tools_.empty()) {
    c.last_check_u = last_u_;
    c.tool_poses = tools_.poses();
    c.tool_stats = tools_.stats();
  }
  if (Cutting* cut = solver_.cutting()) {
    c.severed = cut->severed_since(0);
    c.band = cut->cut_band_state();
    if (!tools_.empty()) c.blade_sides = cut->blade_sides();
    if (!tools_.empty()) c.blades_cutting = cut->blades_cutting();
  }
  if (has_grasper(scene_))
    c.grips = need(solver_.tools(), solver_, "hold a grasper's grip").grips();
  c.aspiration = aspirator_.state();
  return c;
}

void RunLoop::write_checkpoint_now() {
  if (options_.before_checkpoint) options_.before_checkpoint();
  write_checkpoint(options_.out_dir / kCheckpointFile, checkpoint());
  if (std::find(result_.outputs.begin(), result_.outputs.end(), kCheckpointFile) ==
      result_.outputs.end())
    result_.outputs.push_back(kCheckpointFile);
}

void RunLoop::lap(double& into) {
  const auto now = std::chrono::steady_clock::now();
  into += std::chrono::duration<double>(now - mark_).count();
  mark_ = now;
}

void RunLoop::extend(int64_t total) {
  if (within_step_)
    throw std::runtime_error("stopped inside step " + std::to_string(step_ + 1) +
                             " (a step of many substeps with tools or tearing): the state is "
                             "not a step's and cannot go on; resume from a checkpoint");
  if (total < step_)
    throw std::invalid_argument("RunLoop::extend: " + std::to_string(total) +
                                " steps, fewer than the " + std::to_string(step_) + " done");
  total_ = total;
  events_ = load_event_steps(set_, step_time_, total_);
  // A load switching exactly at the step the shorter run ended on: it never applied it.
  if (next_event_ < events_.size() && events_[next_event_] == step_) switch_loads(step_ - 1);
  result_.stopped = false;
  result_.stopped_at_rest = false;
}

RunResult RunLoop::snapshot() {
  result_.steps_done = step_;
  result_.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  result_.simulated_time = double(step_) * step_time_;
  result_.real_time_factor =
      result_.wall_seconds > 0 ? result_.simulated_time / result_.wall_seconds : 0;
  result_.tools = tools_.stats();
  result_.aspirating = aspirator_.active();
  result_.aspiration = aspirator_.totals();
  result_.split.aspiration = aspirator_.times();
  if (!result_.non_finite && !result_.unstable) {
    result_.energies = solver_.energies();
    result_.max_displacement = max_norm(solver_.read_state(false).displacement);
  }
  return result_;
}

RunResult RunLoop::finish() {
  result_.steps_done = step_;
  result_.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (!result_.non_finite && !result_.unstable && !within_step_) {
    // The end (or an interruption, or rest): a last checkpoint to continue from.
    if (options_.checkpoint_every > 0 && checkpointed_ != step_) write_checkpoint_now();
    write_points(step_);
  }
  const double wall = result_.wall_seconds;
  RunResult result = snapshot();
  result.wall_seconds = wall;
  result.real_time_factor = wall > 0 ? result.simulated_time / wall : 0;
  return result;
}

}  // namespace phyxel
