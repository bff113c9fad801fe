// summary.json of a run: what was simulated, how, and the final state in numbers. The file is
// replaced atomically (written to FILE.tmp, then renamed).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "engine/run/simulation.h"
#include "engine/surgery/haptic_session.h"

namespace phyxel::app {

// {"advance", "checks", "callbacks", "pacing", "outputs"}: seconds (RunResult::WallSplit);
// where the run aspirated, "aspiration": the callbacks' aspiration parts (AspirationTimes).
// Inline: bench/ uses it without linking app/.
inline nlohmann::json wall_split_json(const RunResult::WallSplit& split) {
  nlohmann::json j = {{"advance", split.advance},
                      {"checks", split.checks},
                      {"callbacks", split.callbacks},
                      {"pacing", split.pacing},
                      {"outputs", split.outputs}};
  const AspirationTimes& a = split.aspiration;
  if (a.reads > 0)
    j["aspiration"] = {{"reads", a.reads},
                       {"read", a.read},
                       {"sphere", a.sphere},
                       {"rest_map", a.rest_map},
                       {"removal", a.removal}};
  return j;
}

// The summary as JSON (what write_run_summary writes).
nlohmann::json run_summary(const Scene& scene, const PhyxelSet& set, Solver& solver,
                           const RunOptions& options, const RunResult& result,
                           const HapticSession* haptics = nullptr,
                           const char* interrupted_by = nullptr);

void write_run_summary(const std::filesystem::path& file, const Scene& scene, const PhyxelSet& set,
                       Solver& solver, const RunOptions& options, const RunResult& result,
                       const HapticSession* haptics = nullptr,
                       const char* interrupted_by = nullptr);  // "SIGINT" when a signal stopped it

// Why the state failed, one line naming the scene file and what to change (non-finite or
// runaway, beside a tool or not); "" when it did not.
std::string describe_stop(const Scene& scene, const RunResult& result);

}  // namespace phyxel::app
