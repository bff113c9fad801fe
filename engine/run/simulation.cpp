#include "engine/run/simulation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <thread>

#include "engine/run/long_step.h"
#include "engine/run/run_schedule.h"
#include "engine/run/vtp_writer.h"

namespace phyxel {

TimeStepPlan plan_time_step(const Scene& scene, const PhyxelSet& set) {
  TimeStepPlan plan;
  plan.dt_requested = scene.simulation.dt;
  double bound = std::numeric_limits<double>::infinity();
  std::vector<double> speed(set.materials.size());
  for (size_t m = 0; m < set.materials.size(); ++m) speed[m] = p_wave_speed(set.materials[m]);
  for (size_t i = 0; i < set.size(); ++i) {
    if (set.flags[i] & (kFixed | kRemoved)) continue;
    bound = std::min(bound, set.objects[set.object[i]].spacing / speed[set.material[i]]);
  }
  plan.dt_stable = scene.simulation.courant * bound;
  plan.substeps = 1;
  if (plan.dt_requested > plan.dt_stable)
    plan.substeps =
        static_cast<int64_t>(std::ceil(plan.dt_requested / plan.dt_stable * (1 - 1e-12)));
  plan.dt_used = plan.dt_requested / static_cast<double>(plan.substeps);
  if (plan.substeps > 1) {
    char text[256];
    std::snprintf(text, sizeof text,
                  "requested dt %.4g s exceeds the stable step %.4g s (courant %.3g x spacing / "
                  "p-wave speed); each step is split into %lld substeps of %.4g s",
                  plan.dt_requested, plan.dt_stable, scene.simulation.courant,
                  static_cast<long long>(plan.substeps), plan.dt_used);
    plan.reason = text;
  }
  return plan;
}

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

}  // namespace

namespace {

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
        solver.set_object_awake(static_cast<uint32_t>(o), true);
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

}  // namespace

RunResult run_simulation(const Scene& scene, const PhyxelSet& set, Solver& solver,
                         const RunOptions& options) {
  RunResult result;
  result.plan = plan_time_step(scene, set);
  const int64_t total = options.steps;
  const int64_t every = scene.output.every;
  const double step_time = result.plan.dt_requested;
  const bool select = options.pass_selection && solver.supports_pass_selection();
  if (solver.supports_pass_selection()) solver.set_pass_selection(select);
  // Tearing: the largest principal stress of every stressed phyxel, and the overstressed
  // pairs severed, each substep.
  const bool tearing = scene.tearing_possible();
  if (tearing && !solver.supports_tearing())
    throw std::runtime_error(scene.file.string() + ": a material has tear_stress, which " +
                             solver.device() + " cannot evaluate; use --device cpu");
  if (solver.supports_principal_stress()) solver.set_principal_stress(tearing);
  if (solver.supports_tearing()) solver.set_tearing(tearing);
  const SleepSettings& sleep = scene.simulation.sleep;
  const bool sleeping = select && sleep.enabled;
  const UntilRest& rest = scene.simulation.until_rest;
  const std::vector<int64_t> events = load_event_steps(set, step_time, total);
  if (!events.empty() && !solver.supports_load_changes())
    throw std::runtime_error(scene.file.string() +
                             ": loads with from/until switch during the run, "
                             "which " +
                             solver.device() + " cannot do; use --device cpu");
  const int64_t check = check_interval(scene, options, sleeping);
  ToolTrack tools(scene.tools, options.tool_pose);
  // Per tool, the most phyxels in contact at a step since the last check (RunResult's
  // non_finite_tool).
  std::vector<uint32_t> contacts_since_check(tools.size(), 0u);
  Aspirator aspirator(scene, set);
  if (aspirator.active() && !solver.supports_removal())
    throw std::runtime_error(scene.file.string() + ": a suction tool aspirates tissue, which " +
                             solver.device() + " cannot remove; use --device cpu or gpu");
  if (aspirator.active() && (options.checkpoint_every > 0 || options.resume))
    throw std::runtime_error(scene.file.string() +
                             ": checkpoints do not hold aspirated tissue yet; run a scene whose "
                             "suction tools aspirate without --checkpoint-every or --resume");
  if (has_grasper(scene) && (options.checkpoint_every > 0 || options.resume))
    throw std::runtime_error(scene.file.string() +
                             ": checkpoints do not hold a grasper's grip yet; run a scene with a "
                             "grasper without --checkpoint-every or --resume");
  if (!tools.empty()) {
    if (!solver.supports_tools())
      throw std::runtime_error(scene.file.string() + ": the scene has tools, which " +
                               solver.device() + " cannot simulate; use --device cpu");
    solver.set_tools(contact_tools(scene.tools));
  }
  // Steps per advance while tools move: the broad phase is built once per advance.
  const int64_t tool_chunk =
      tools.empty() ? 0 : std::max<int64_t>(1, options.tool_chunk_substeps / result.plan.substeps);
  // Each sleeping object's displacement when it went to sleep (its u does not change asleep).
  std::vector<Vec3> last_u(set.size(), Vec3::Zero());
  double slowest_wave = std::numeric_limits<double>::infinity();  // find_runaway's bound
  for (const Material& m : set.materials) slowest_wave = std::min(slowest_wave, p_wave_speed(m));
  int64_t below_since = -1;
  std::vector<int64_t> object_below_since(set.objects.size(), -1);
  std::vector<uint8_t> awake(set.objects.size(), 1);
  const int64_t checkpoint_every = options.checkpoint_every;
  if (checkpoint_every > 0 && options.out_dir.empty())
    throw std::runtime_error("checkpoints need an output folder");
  const uint64_t scene_hash =
      (checkpoint_every > 0 || options.resume) && !scene.file.empty() ? file_hash(scene.file) : 0;

  auto write_points = [&](int64_t step) {
    if (options.out_dir.empty()) return;
    PointState state = solver.read_state(true);
    // The solvers always report a contact flag per phyxel (all 0 without tools); the .vtp
    // files carry the `contact` array for scenes with tools only.
    if (scene.tools.empty()) state.contact.clear();
    const std::string name = points_name(step);
    write_points_vtp(options.out_dir / name, set, state, scene.output.binary);
    result.outputs.push_back(name);
    if (options.on_points_written) options.on_points_written(name);
  };
  auto next_multiple = [](int64_t step, int64_t n) { return (step / n + 1) * n; };

  // Advances without tools split exactly, so they can be cut short to see a stop promptly.
  const bool polled = options.stop_requested && tools.empty();
  int64_t poll_steps = 1;  // steps per advance while polled, from the measured rate
  // Steps of many substeps are polled between substeps too (engine/run/long_step.h).
  const bool long_steps = polled && !tearing && result.plan.substeps >= kLongStepSubsteps;

  int64_t step = 0;
  size_t next_event = 0;
  // Loads switch at `step` (after `previous`): apply the new ones and wake every object whose
  // loads changed.
  auto switch_loads = [&](int64_t previous) {
    ++next_event;
    ++result.load_changes;
    solver.set_external_forces(external_forces_at(set, step * step_time));
    for (const LoadSpread& load : set.loads) {
      if (load.active_at(previous * step_time) == load.active_at(step * step_time)) continue;
      object_below_since[load.object] = -1;
      if (!awake[load.object]) {
        awake[load.object] = 1;
        solver.set_object_awake(load.object, true);
        ++result.wakes;
      }
    }
  };
  if (options.resume) {
    const Checkpoint& c = *options.resume;
    const std::string name = (options.out_dir / kCheckpointFile).string();
    check_checkpoint_matches(c, name, scene_hash, set, solver.device());
    if (c.dt_requested != step_time || c.substeps != result.plan.substeps || c.check_every != check)
      throw CheckpointError(name +
                            ": written with another time step, substep count or check "
                            "interval (--check-every) than this run's");
    if (c.step > total)
      throw CheckpointError(name + ": at step " + std::to_string(c.step) + ", past the " +
                            std::to_string(total) + " steps this run is asked for");
    if (c.loads_applied > static_cast<int64_t>(events.size()) ||
        (c.loads_applied > 0 && events[c.loads_applied - 1] > c.step) ||
        c.tool_stats.size() != tools.size() ||
        (!tools.empty() && c.last_check_u.size() != set.size()))
      throw CheckpointError(name + ": its load schedule or tools differ from the scene's");
    step = c.step;
    result.resumed_from = c.step;
    result.sleeps = c.sleeps;
    result.wakes = c.wakes;
    result.load_changes = c.load_changes;
    next_event = static_cast<size_t>(c.loads_applied);
    if (next_event > 0)
      solver.set_external_forces(external_forces_at(set, events[next_event - 1] * step_time));
    for (size_t o = 0; o < set.objects.size(); ++o) {
      awake[o] = c.awake[o];
      object_below_since[o] = c.object_below_since[o];
      if (!awake[o]) solver.set_object_awake(static_cast<uint32_t>(o), false);
    }
    below_since = c.rest_below_since;
    if (!tools.empty()) {
      last_u = c.last_check_u;
      tools.restore(c.tool_poses, c.tool_stats);
    }
    solver.sever_pairs(c.severed);                 // the cuts, before the state's forces
    solver.set_state(c.displacement, c.velocity);  // last: the forces for this u and state
    // A load switching exactly at the step a shorter run ended on: it never applied it.
    if (next_event < events.size() && events[next_event] == step) switch_loads(step - 1);
    // A run that had come to rest stays finished (its last check said so).
    if (rest.enabled && below_since >= 0 && step - below_since >= rest.for_steps)
      result.stopped_at_rest = true;
    // summary.json lists the whole run's outputs: the snapshots written before the checkpoint.
    for (int64_t s = every; every > 0 && s <= step && s < total; s += every)
      result.outputs.push_back(points_name(s));
  }
  auto write_checkpoint_now = [&] {
    if (options.before_checkpoint) options.before_checkpoint();
    Checkpoint c = make_checkpoint(scene, set, solver, scene_hash, step, result);
    c.check_every = check;
    c.checkpoint_every = checkpoint_every;
    c.total = total;
    c.awake = awake;
    c.object_below_since = object_below_since;
    c.loads_applied = static_cast<int64_t>(next_event);
    c.rest_below_since = below_since;
    if (!tools.empty()) {
      c.last_check_u = last_u;
      c.tool_poses = tools.poses();
      c.tool_stats = tools.stats();
    }
    c.severed = solver.severed_since(0);
    write_checkpoint(options.out_dir / kCheckpointFile, c);
    if (std::find(result.outputs.begin(), result.outputs.end(), kCheckpointFile) ==
        result.outputs.end())
      result.outputs.push_back(kCheckpointFile);
  };

  int64_t checkpointed = options.resume ? step : -1;  // the step of the last checkpoint
  const auto start = std::chrono::steady_clock::now();
  // Real-time pacing counts simulated time from step 0: a resumed run's clock starts where the
  // checkpoint's simulated time was.
  const auto paced_from = start - std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                      std::chrono::duration<double>(double(step) * step_time));
  while (step < total && !result.stopped_at_rest) {
    // Advance to the next step at which something has to be looked at.
    int64_t next = std::min(total, next_multiple(step, check));
    if (every > 0) next = std::min(next, next_multiple(step, every));
    if (options.frame_every > 0) next = std::min(next, next_multiple(step, options.frame_every));
    if (next_event < events.size()) next = std::min(next, events[next_event]);
    // Tool chunks on a fixed grid from step 0, whatever else splits an advance (frames,
    // outputs, checks, real-time pacing): the aspirator acts only at its lines, so what is
    // aspirated does not depend on how often frames are drawn.
    if (tool_chunk > 0) next = std::min(next, next_multiple(step, tool_chunk));
    if (checkpoint_every > 0) next = std::min(next, next_multiple(step, checkpoint_every));
    // Real time: advance what the wall clock owes (at least a step, at most a tool chunk), so
    // a live tool's pose reaches the physics every few milliseconds of wall time.
    if (options.real_time) next = std::min(next, step + steps_owed(paced_from, step, step_time));
    // A stop can be asked for: advance no more than about stop_poll_seconds of wall time.
    if (polled) next = std::min(next, step + poll_steps);
    if (!tools.empty())  // sleeping objects the tools are about to reach wake first
      wake_touched_objects(set, tools.swept_bounds(step * step_time, next * step_time), last_u,
                           awake, object_below_since, solver, result);
    auto mark = std::chrono::steady_clock::now();
    auto lap = [&mark](double& into) {
      const auto now = std::chrono::steady_clock::now();
      into += std::chrono::duration<double>(now - mark).count();
      mark = now;
    };
    const auto advance_start = mark;
    std::vector<ToolStepRecord> records;
    if (long_steps)  // a stop mid-step ends the run at the last whole step
      next = step + advance_long_steps(solver, next - step, result.plan.substeps,
                                       result.plan.dt_used, options.stop_requested,
                                       options.stop_poll_seconds, options.on_substep_rate);
    else
      records = advance_with_tools(solver, tools, step, next - step, result.plan.substeps,
                                   result.plan.dt_used);
    for (size_t r = 0; r < records.size(); ++r) {
      uint32_t& most = contacts_since_check[r % tools.size()];
      most = std::max(most, records[r].contacts);
    }
    if (polled)
      poll_steps = steps_within(options.stop_poll_seconds, next - step, advance_start, poll_steps);
    lap(result.split.advance);
    for (int64_t s = step; options.on_tool_step && !tools.empty() && s < next; ++s)
      options.on_tool_step(
          s + 1, double(s + 1) * step_time,
          std::vector<ToolStepRecord>(records.begin() + (s - step) * tools.size(),
                                      records.begin() + (s - step + 1) * tools.size()));
    // The paper's hybrid tearing at the aspirators' mouths, at the end of each tool chunk.
    if (aspirator.active() && tool_chunk > 0 && (next % tool_chunk == 0 || next == total))
      for (const AspirationEvent& e :
           aspirator.after_advance(solver, tools.poses(), double(next) * step_time))
        if (options.on_aspiration) options.on_aspiration(e);
    lap(result.split.callbacks);
    if (options.real_time) pace(paced_from, double(next) * step_time, result);
    lap(result.split.pacing);
    const int64_t previous = step;
    step = next;
    if (options.progress) options.progress(step, total);

    if (next_event < events.size() && events[next_event] == step) switch_loads(previous);

    // Checkpoints hold the state a run that goes on has at this step: after the check where the
    // loop checks, before the end's extra check (its sleep and rest decisions) where it does
    // not. Adding checkpoints thus changes no decision of the loop.
    const bool regular = step % check == 0;
    if (checkpoint_every > 0 && (step % checkpoint_every == 0 || step == total) && !regular &&
        solver.first_non_finite() < 0) {
      write_checkpoint_now();
      checkpointed = step;
    }
    const bool checking = regular || step == total;
    if (checking) {
      const long bad = solver.first_non_finite();
      if (bad >= 0) {
        result.non_finite = true;
        result.non_finite_step = step;
        result.non_finite_phyxel = bad;
        for (size_t k = 0; k < contacts_since_check.size(); ++k) {
          if (contacts_since_check[k] > result.non_finite_tool_contacts) {
            result.non_finite_tool = static_cast<int>(k);
            result.non_finite_tool_contacts = contacts_since_check[k];
          }
        }
        break;
      }
      std::fill(contacts_since_check.begin(), contacts_since_check.end(), 0u);
    }
    // The checks read reductions: per object its kinetic energy and largest speed where rest or
    // sleep is decided, else the largest speed alone. Only a phyxel faster than the slowest
    // wave speed (a runaway to name) or an object going to sleep near tools reads u or v back.
    if (checking) {
      std::vector<ObjectMotion> motion;
      double fastest = 0;
      if (rest.enabled || sleeping) {
        motion = solver.object_motion(set);
        for (const ObjectMotion& m : motion)
          if (!(m.max_speed <= fastest)) fastest = m.max_speed;
      } else {
        fastest = solver.max_norms().second;
      }
      if (!(fastest <= slowest_wave)) {
        const PointState state = solver.read_state(false);
        if (const Runaway r = find_runaway(set, state.velocity); r.phyxel >= 0) {
          result.unstable = true;
          result.unstable_step = step;
          result.unstable_phyxel = r.phyxel;
          result.unstable_speed = r.speed;
          result.unstable_wave_speed = r.wave_speed;
          const Vec3 x = set.rest[r.phyxel] + state.displacement[r.phyxel];
          double near = 0;
          for (const ObjectRange& o : set.objects)
            if (r.phyxel >= long(o.first) && r.phyxel < long(o.first + o.count))
              near = 2 * o.support_radius;
          for (size_t k = 0; k < tools.size(); ++k) {
            const double d = tool_distance(tools.shape(k), tools.poses()[k], x).distance;
            if (d <= near && (result.unstable_tool < 0 || d < result.unstable_tool_distance)) {
              result.unstable_tool = static_cast<int>(k);
              result.unstable_tool_distance = d;
            }
          }
          break;
        }
      }
      double kinetic = 0;
      for (const ObjectMotion& m : motion) kinetic += m.kinetic;
      if (rest.enabled) {
        if (kinetic >= rest.kinetic_energy_below) {
          below_since = -1;
        } else if (below_since < 0) {
          below_since = step;
        }
        if (below_since >= 0 && step - below_since >= rest.for_steps) result.stopped_at_rest = true;
      }
      std::vector<Vec3> u_now;  // read back once, for the objects that go to sleep now
      for (size_t o = 0; sleeping && o < set.objects.size(); ++o) {
        if (!awake[o]) continue;
        if (motion[o].kinetic >= sleep.kinetic_energy_below) {
          object_below_since[o] = -1;
        } else if (object_below_since[o] < 0) {
          object_below_since[o] = step;
        }
        if (object_below_since[o] >= 0 && step - object_below_since[o] >= sleep.for_steps) {
          awake[o] = 0;
          solver.set_object_awake(static_cast<uint32_t>(o), false);
          ++result.sleeps;
          if (!tools.empty()) {  // where it sleeps, for wake_touched_objects
            if (u_now.empty()) u_now = solver.read_state(false).displacement;
            const ObjectRange& obj = set.objects[o];
            std::copy(u_now.begin() + obj.first, u_now.begin() + obj.first + obj.count,
                      last_u.begin() + obj.first);
          }
        }
      }
    }
    lap(result.split.checks);
    result.stopped = step < total && !result.stopped_at_rest && options.stop_requested &&
                     options.stop_requested();
    const bool last = step == total || result.stopped_at_rest || result.stopped;
    if (every > 0 && step % every == 0 && !last) write_points(step);
    if (options.on_frame && options.frame_every > 0 && (step % options.frame_every == 0 || last))
      options.on_frame(step, solver);
    if (checkpoint_every > 0 && step % checkpoint_every == 0 && regular) {
      write_checkpoint_now();
      checkpointed = step;
    }
    lap(result.split.outputs);
    if (result.stopped_at_rest || result.stopped) break;
  }
  result.steps_done = step;
  result.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.simulated_time = double(step) * step_time;
  result.real_time_factor =
      result.wall_seconds > 0 ? result.simulated_time / result.wall_seconds : 0;
  result.tools = tools.stats();
  result.aspirating = aspirator.active();
  result.aspiration = aspirator.totals();
  if (!result.non_finite && !result.unstable) {
    // The end (or an interruption, or rest): a last checkpoint to continue from.
    if (checkpoint_every > 0 && checkpointed != step) write_checkpoint_now();
    write_points(step);
    result.energies = solver.energies();
    result.max_displacement = max_norm(solver.read_state(false).displacement);
  }
  return result;
}

std::vector<ToolStepRecord> advance_with_tools(Solver& solver, ToolTrack& tools, int64_t first,
                                               int64_t steps, int64_t substeps, double dt) {
  if (tools.empty()) {
    solver.advance(steps * substeps, dt);
    return {};
  }
  solver.set_tool_motion(tools.motions(first * substeps, steps * substeps, dt));
  solver.advance(steps * substeps, dt);
  return tools.fold(solver.tool_samples(), steps, substeps);
}

Runaway find_runaway(const PhyxelSet& set, const std::vector<Vec3>& velocity) {
  std::vector<double> wave_speed(set.materials.size());
  for (size_t m = 0; m < set.materials.size(); ++m) wave_speed[m] = p_wave_speed(set.materials[m]);
  Runaway r;
  for (size_t i = 0; i < set.size() && i < velocity.size(); ++i) {
    const double v2 = velocity[i].squaredNorm();
    const double c = wave_speed[set.material[i]];
    if (v2 > c * c) {
      r.phyxel = static_cast<long>(i);
      r.speed = std::sqrt(v2);
      r.wave_speed = c;
      break;
    }
  }
  return r;
}

}  // namespace phyxel
