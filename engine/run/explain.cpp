// phyxel run --explain: the pass plan of a scene on a solver (engine/run/simulation.h).
#include <algorithm>
#include <cstdio>
#include <sstream>
#include <string>

#include "engine/run/run_schedule.h"
#include "engine/run/simulation.h"

namespace phyxel {

namespace {

// The tool passes of a scene with tools (explain_passes).
template <class Add>
void explain_tools(const Scene& scene, const RunOptions& options, const TimeStepPlan& plan,
                   size_t phyxels, size_t scalpels, Add& add) {
  add("    contact        %zu tool(s): after every drift, on the phyxels whose current "
      "position is near the tools' swept bounds (broad phase once per advance of at most %lld "
      "substeps); the tools' forces are summed per substep",
      scene.tools.size(), static_cast<long long>(tool_chunk_substeps(options, phyxels)));
  if (scalpels > 0) {
    add("    cut            %zu scalpel(s): after the contact, on the same candidates (their "
        "margin grown by the support radius), the pairs crossing the blade's swept quad "
        "severed at the threshold or once the edge carries them past its reach; then the "
        "precompute of their phyxels",
        scalpels);
    add("                   at threshold 0, none in an advance whose candidates all lie beyond "
        "the blades' reach");
  }
  const auto aspirators = std::count_if(scene.tools.begin(), scene.tools.end(),
                                        [](const ToolDesc& t) { return t.suction.sucks(); });
  if (aspirators > 0 && scene.tearing_possible())
    add("    suction        %zu aspirator(s): their pull in the contact pass; the fracture "
        "sphere at each mouth every %lld steps (state read back while on)",
        static_cast<size_t>(aspirators),
        static_cast<long long>(
            tool_chunk_steps(scene, options, phyxels, plan.substeps, plan.dt_requested)));
  else if (aspirators > 0)
    add("    suction        %zu aspirator(s): their pull in the contact pass; nothing "
        "aspirated (no material has tear_stress)",
        static_cast<size_t>(aspirators));
  const auto graspers = std::count_if(scene.tools.begin(), scene.tools.end(),
                                      [](const ToolDesc& t) { return t.grasp.grasps(); });
  if (graspers > 0)
    add("    grasp          %zu grasper(s): after the contact, while the jaws are closed, the "
        "phyxels they hold carried with the tool (captured from the candidates within reach "
        "when they close) and the grip's force summed per substep",
        static_cast<size_t>(graspers));
  add("  tools: tools.csv (a row per step and tool) and summary.json tools");
}

}  // namespace

std::string explain_passes(const Scene& scene, const PhyxelSet& set, Solver& solver,
                           const RunOptions& options) {
  const TimeStepPlan plan = plan_time_step(scene, set);
  PassSelection* passes = solver.pass_selection();
  const bool select = options.pass_selection && passes;
  if (passes) passes->set_pass_selection(select);
  size_t fixed = 0;
  for (uint32_t f : set.flags) fixed += (f & kFixed) ? 1 : 0;
  const size_t n = set.size(), moving = n - fixed;
  std::ostringstream out;
  char line[320];
  auto add = [&](const char* fmt, auto... args) {
    std::snprintf(line, sizeof line, fmt, args...);
    out << line << "\n";
  };
  add("pass plan for %s: %zu phyxels in %zu object(s), %zu fixed, on %s",
      scene.file.string().c_str(), n, set.objects.size(), fixed, solver.device().c_str());
  add("  time step: requested %.4g s, stable bound %.4g s -> %lld substep(s) of %.4g s",
      plan.dt_requested, plan.dt_stable, static_cast<long long>(plan.substeps), plan.dt_used);
  add("  per substep:");
  add("    kick + drift   %zu phyxels (fixed ones never move)", moving);
  if (select) {
    const size_t stress = passes->stress_pass_size();
    add("    stress (MLS)   %zu phyxels: the moving ones and their neighbours; %zu fixed-only "
        "phyxels skipped",
        stress, n - stress);
    add("    force + kick   %zu phyxels: the moving ones", passes->force_pass_size());
  } else if (passes) {
    add("    stress (MLS)   %zu phyxels: all (--no-skip)", n);
    add("    force + kick   %zu phyxels: all, fixed ones for their reactions (--no-skip)", n);
  } else {
    add("    stress (MLS)   %zu phyxels: all (this device has no pass selection)", n);
    add("    force + kick   %zu phyxels: all", n);
  }
  const size_t tear_materials = static_cast<size_t>(std::count_if(
      set.materials.begin(), set.materials.end(), [](const Material& m) { return m.tear_stress; }));
  const bool tearing = scene.tearing_possible();
  if (tearing)
    add("    principal      %zu phyxels (those of the stress pass): the largest principal "
        "Cauchy stress, for tearing (%zu material(s) with tear_stress)",
        select ? passes->stress_pass_size() : n, tear_materials);
  if (tearing)
    add("    tear           the same phyxels after the forces, in the force pass's dispatch: "
        "each live pair whose mean normal stress reaches the mean tear_stress of its two "
        "phyxels is severed; then the precompute of the phyxels it touched only");
  const bool sleeping = select && scene.simulation.sleep.enabled;
  if (sleeping)
    add("  sleeping: on; an object whose kinetic energy stays below %.3g J for %lld steps "
        "sleeps (all its passes skipped) until one of its loads switches",
        scene.simulation.sleep.kinetic_energy_below,
        static_cast<long long>(scene.simulation.sleep.for_steps));
  else
    add("  sleeping: off (%s)", !scene.simulation.sleep.enabled ? "no simulation.sleep in the scene"
                                : select                        ? ""
                                                                : "--no-skip");
  const auto events = load_event_steps(set, plan.dt_requested, options.steps);
  add("  load changes: %zu (loads with from/until)", events.size());
  const bool energies = scene.simulation.until_rest.enabled || sleeping;
  add("  checks: finiteness and the largest speed every %lld steps%s",
      static_cast<long long>(
          check_interval(scene, options, sleeping,
                         tool_chunk_steps(scene, options, n, plan.substeps, plan.dt_requested))),
      energies ? ", with kinetic energies (the state read back) for until_rest or sleep"
               : "; the state is read back only when a phyxel outruns the slowest wave speed");
  if (scene.output.every > 0)
    add("  outputs: points_*.vtp every %lld steps and at the end; no readback otherwise",
        static_cast<long long>(scene.output.every));
  else
    add("  outputs: points_*.vtp at the end only; no readback otherwise");
  const bool rendering = scene.render.mode != RenderSettings::Mode::None;
  if (rendering)
    add("  render: %s frames at step 0, every %lld steps and at the end (offscreen, PNG)",
        scene.render.mode == RenderSettings::Mode::Stereo ? "stereo" : "mono",
        static_cast<long long>(scene.render.every));
  const auto scalpels = std::count_if(scene.tools.begin(), scene.tools.end(),
                                      [](const ToolDesc& t) { return t.blade.cuts(); });
  if (!scene.tools.empty())
    explain_tools(scene, options, plan, n, static_cast<size_t>(scalpels), add);
  // What the scene does not need, with the reason; nothing when it needs everything.
  std::string skipped;
  for (const char* part : {rendering ? "" : "render passes (render.mode none)",
                           scene.tools.empty() ? "contact passes (no tool)" : "",
                           tearing ? ""
                                   : "principal stress and tear passes (no material has "
                                     "tear_stress)",
                           scalpels > 0 ? "" : "cutting passes (no scalpel)",
                           has_grasper(scene) ? "" : "grasp passes (no grasper)"})
    if (*part) {
      if (!skipped.empty()) skipped += ", ";
      skipped += part;
    }
  add("  not recorded: %s", skipped.empty() ? "nothing" : skipped.c_str());
  return out.str();
}

}  // namespace phyxel
