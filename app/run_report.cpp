#include "app/run_report.h"

#include "engine/surgery/resection.h"

#include "engine/run/atomic_file.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace phyxel::app {

namespace {

using nlohmann::json;

// Per object: its phyxels, spacing, support radius and neighbour counts.
json objects_json(const PhyxelSet& set, Solver& solver) {
  json objects = json::array();
  const NeighbourLists& nbr = solver.neighbours();
  for (const ObjectRange& o : set.objects) {
    uint32_t lo = UINT32_MAX, hi = 0;
    uint64_t sum = 0;
    for (uint32_t i = o.first; i < o.first + o.count; ++i) {
      lo = std::min(lo, nbr.count(i));
      hi = std::max(hi, nbr.count(i));
      sum += nbr.count(i);
    }
    objects.push_back(
        {{"name", o.name},
         {"phyxels", o.count},
         {"spacing", o.spacing},
         {"support_radius", o.support_radius},
         {"neighbours",
          {{"min", lo}, {"max", hi}, {"mean", o.count ? double(sum) / o.count : 0.0}}}});
  }
  return objects;
}

// Per tool: the last and largest force and contacts; a blade's cut, a grasper's hold.
json tools_json(const std::vector<ToolRunStats>& stats) {
  json tools = json::array();
  for (const ToolRunStats& t : stats) {
    json tool = {{"name", t.name},
                 {"force", {t.last_force.x(), t.last_force.y(), t.last_force.z()}},
                 {"max_force", t.max_force},
                 {"contacts", t.contacts},
                 {"max_contacts", t.max_contacts},
                 {"steps_in_contact", t.steps_in_contact}};
    if (t.cuts) {
      tool["max_cut_force"] = t.max_cut_force;
      tool["cutting_substeps"] = t.cutting_substeps;
      tool["max_feedback_force"] = t.max_feedback;
      tool["max_friction_force"] = t.max_friction;
      tool["max_penetration_depth"] = t.max_depth;
    }
    if (t.grasps) {  // engine/solver/grasper.h
      tool["held"] = t.held;
      tool["max_held"] = t.max_held;
      tool["max_pull_force"] = t.max_pull_force;
    }
    tools.push_back(tool);
  }
  return tools;
}

// What the cuts and tears freed from the fixed tissue (engine/surgery/resection.h).
json cutting_json(const Scene& scene, const PhyxelSet& set, Solver& solver, Cutting& cut) {
  const Resection r = measure_resection(scene, set, solver.neighbours(), cut.pair_alive());
  json inclusions = json::array();
  for (const InclusionRemoval& c : r.inclusions)
    inclusions.push_back({{"name", c.name},
                          {"mass_g", 1e3 * c.mass},
                          {"removed_percent", c.mass > 0 ? 100 * c.removed / c.mass : 0.0},
                          {"healthy_removed_g", 1e3 * c.healthy_removed},
                          {"whole", c.whole}});
  size_t torn = 0;
  for (const SeveredPair& p : cut.severed_since(0)) torn += p.torn;
  return {{"severed_pairs", cut.severed_pairs()},
          {"cut_pairs", cut.severed_pairs() - torn},
          {"torn_pairs", torn},
          {"freed_pieces", r.pieces},
          {"freed_mass_g", 1e3 * r.freed_mass},
          {"inclusions", inclusions}};
}

// What the aspirators took (engine/surgery/aspiration.h), per object and inclusion.
json aspiration_json(const AspirationTotals& a) {
  json parts = json::array();
  double removed = 0;
  for (size_t m = 0; m < a.names.size(); ++m) {
    removed += a.removed_mass[m];
    parts.push_back({{"name", a.names[m]},
                     {"mass_g", 1e3 * a.initial_mass[m]},
                     {"removed_g", 1e3 * a.removed_mass[m]},
                     {"removed_percent",
                      a.initial_mass[m] > 0 ? 100 * a.removed_mass[m] / a.initial_mass[m] : 0.0},
                     {"removed_volume_cm3", 1e6 * a.removed_volume[m]}});
  }
  return {{"events", a.events},
          {"largest_fracture_radius_m", a.max_radius},
          {"removed_g", 1e3 * removed},
          {"parts", parts}};
}

// Per haptic loop: its timing and forces; a UDP device's senders.
json haptics_json(const HapticSession& haptics) {
  json loops = json::array();
  for (const HapticSession::ToolLoop& l : haptics.loops()) {
    const HapticStats st = l.loop->stats();
    loops.push_back({{"tool", l.name},
                     {"device", l.loop->device().name()},
                     {"ticks", st.ticks},
                     {"period_mean_ms", st.period_mean_ms},
                     {"period_p99_ms", st.period_p99_ms},
                     {"period_max_ms", st.period_max_ms},
                     {"overruns", st.overruns},
                     {"max_force_jump", st.max_force_jump},
                     {"max_hand_force", st.max_hand_force},
                     {"snapshots", st.snapshots},
                     {"realtime_priority", st.realtime_priority},
                     {"speed_limited_ticks", st.speed_limited_ticks}});
    // A scene without tissue leaves the tool's speed unbounded: null.
    loops.back()["top_speed"] = std::isfinite(st.top_speed) ? json(st.top_speed) : json(nullptr);
    if (const auto* udp = dynamic_cast<const UdpDevice*>(&l.loop->device())) {
      // Who drove the tool: the pinned sender's poses; the others' dropped (UdpDevice).
      const UdpDeviceStats u = udp->stats();
      loops.back()["udp"] = {{"poses", u.poses},
                             {"senders_pinned", u.pins},
                             {"foreign_dropped", u.foreign},
                             {"refused_dropped", u.refused},
                             {"malformed", u.malformed},
                             {"stale", u.stale}};
    }
  }
  return loops;
}

// Where the state failed (non-finite or runaway, and the tool beside it), else its energies.
void add_final_state(json& j, const Scene& scene, const RunResult& result) {
  if (result.non_finite) {
    j["non_finite_at"] = {{"step", result.non_finite_step}, {"phyxel", result.non_finite_phyxel}};
    if (result.non_finite_tool >= 0)
      j["non_finite_at"]["tool_in_contact"] = {
          {"name", scene.tools.at(result.non_finite_tool).name},
          {"max_contacts", result.non_finite_tool_contacts}};
  } else if (result.unstable) {
    j["unstable_at"] = {{"step", result.unstable_step},
                        {"phyxel", result.unstable_phyxel},
                        {"speed", result.unstable_speed},
                        {"p_wave_speed", result.unstable_wave_speed}};
    if (result.unstable_tool >= 0)
      j["unstable_at"]["nearest_tool"] = {{"name", scene.tools.at(result.unstable_tool).name},
                                          {"distance", result.unstable_tool_distance}};
  } else {
    j["kinetic_energy"] = result.energies.kinetic;
    j["strain_energy"] = result.energies.strain;
    j["potential_energy"] = result.energies.potential;
    j["max_displacement"] = result.max_displacement;
  }
}

}  // namespace

nlohmann::json run_summary(const Scene& scene, const PhyxelSet& set, Solver& solver,
                           const RunOptions& options, const RunResult& result,
                           const HapticSession* haptics, const char* interrupted_by) {
  const double substeps_done =
      static_cast<double>(result.steps_done) * static_cast<double>(result.plan.substeps);
  // A resumed run's wall time covers the steps since its checkpoint only.
  const double substeps_timed =
      static_cast<double>(result.steps_done - std::max<int64_t>(0, result.resumed_from)) *
      static_cast<double>(result.plan.substeps);
  json j = {
      {"scene", scene.file.string()},
      {"refine", scene.refine},
      {"device", solver.device()},
      {"phyxels", set.size()},
      {"objects", objects_json(set, solver)},
      {"steps_requested", options.steps},
      {"steps_done", result.steps_done},
      {"substeps_per_step", result.plan.substeps},
      {"substeps_done", substeps_done},
      {"substep_reason", result.plan.reason},
      {"dt_requested", result.plan.dt_requested},
      {"dt_used", result.plan.dt_used},
      {"dt_stable_bound", result.plan.dt_stable},
      {"courant", scene.simulation.courant},
      {"simulated_time", substeps_done * result.plan.dt_used},
      {"wall_seconds", result.wall_seconds},
      {"phyxel_steps_per_second",
       result.wall_seconds > 0 ? double(set.size()) * substeps_timed / result.wall_seconds : 0.0},
      {"resumed_from_step", result.resumed_from},
      {"checkpoint_every", options.checkpoint_every},
      {"stopped_at_rest", result.stopped_at_rest},
      {"interrupted", interrupted_by != nullptr},
      {"ill_conditioned_moment_matrices", solver.regularised_count()},
      {"non_finite", result.non_finite},
      {"unstable", result.unstable},
      {"pass_selection", options.pass_selection && solver.pass_selection() != nullptr},
      {"sleeps", result.sleeps},
      {"wakes", result.wakes},
      {"load_changes", result.load_changes},
      {"outputs", result.outputs},
      {"real_time_factor", result.real_time_factor},
  };
  if (interrupted_by != nullptr) j["interrupted_by"] = interrupted_by;
  if (options.real_time) j["max_lag_seconds"] = result.max_lag;
  j["wall_split_seconds"] = wall_split_json(result.split);
  if (!result.tools.empty()) j["tools"] = tools_json(result.tools);
  if (Cutting* cut = solver.cutting(); cut && cut->severed_pairs() > 0)
    j["cutting"] = cutting_json(scene, set, solver, *cut);
  if (result.aspirating) j["aspiration"] = aspiration_json(result.aspiration);
  if (haptics != nullptr && !haptics->empty()) j["haptics"] = haptics_json(*haptics);
  add_final_state(j, scene, result);
  return j;
}

void write_run_summary(const std::filesystem::path& file, const Scene& scene, const PhyxelSet& set,
                       Solver& solver, const RunOptions& options, const RunResult& result,
                       const HapticSession* haptics, const char* interrupted_by) {
  write_file_atomically(
      file,
      run_summary(scene, set, solver, options, result, haptics, interrupted_by).dump(2) + "\n");
}

std::string describe_stop(const Scene& scene, const RunResult& result) {
  char text[8192];
  const char* file = scene.file.c_str();
  if (result.non_finite && result.non_finite_tool >= 0) {
    std::snprintf(text, sizeof text,
                  "%s: the simulation became non-finite by step %lld (phyxel %ld) while tool '%s' "
                  "pressed on the tissue (up to %u phyxels in contact); stopped. A tool that "
                  "deforms tissue past what this time step holds (tissue that cannot tear, "
                  "stretched around a tool ploughing through it, or a tool too fast) does this: "
                  "slow the tool, give the material a tear_stress so that it tears "
                  "(docs/tearing.md), or lower simulation.courant",
                  file, static_cast<long long>(result.non_finite_step), result.non_finite_phyxel,
                  scene.tools[result.non_finite_tool].name.c_str(),
                  result.non_finite_tool_contacts);
  } else if (result.non_finite) {
    std::snprintf(text, sizeof text,
                  "%s: the simulation became non-finite by step %lld (phyxel %ld); stopped. Lower "
                  "simulation.dt or simulation.courant, or check the material",
                  file, static_cast<long long>(result.non_finite_step), result.non_finite_phyxel);
  } else if (result.unstable && result.unstable_tool >= 0) {
    std::snprintf(text, sizeof text,
                  "%s: the simulation is unstable: at step %lld phyxel %ld, %.1f mm from tool "
                  "'%s', moves at %.3g m/s, faster than sound in its material (%.3g m/s); stopped "
                  "before it turned non-finite. The tool deforms the tissue there past what this "
                  "time step holds (tissue that cannot tear, stretched around a tool ploughing "
                  "through it, or a tool too fast): slow the tool, give the material a "
                  "tear_stress so that it tears (docs/tearing.md), or lower simulation.courant",
                  file, static_cast<long long>(result.unstable_step), result.unstable_phyxel,
                  1e3 * std::max(result.unstable_tool_distance, 0.0),
                  scene.tools[result.unstable_tool].name.c_str(), result.unstable_speed,
                  result.unstable_wave_speed);
  } else if (result.unstable) {
    std::snprintf(text, sizeof text,
                  "%s: the simulation is unstable: at step %lld phyxel %ld moves at %.3g m/s, "
                  "faster than sound in its material (%.3g m/s), which no elastic tissue does; "
                  "stopped before it turned non-finite. The time step is too large for the "
                  "material or a load is far too strong: lower simulation.courant or "
                  "simulation.dt, or the load",
                  file, static_cast<long long>(result.unstable_step), result.unstable_phyxel,
                  result.unstable_speed, result.unstable_wave_speed);
  } else {
    return "";
  }
  return text;
}

}  // namespace phyxel::app
