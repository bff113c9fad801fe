// summary.json of a run: what was simulated, how, and the final state in numbers. The file is
// replaced atomically (written to FILE.tmp, then renamed).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>

#include "engine/run/simulation.h"
#include "engine/surgery/haptic_session.h"

namespace phyxel::app {

// {"advance", "checks", "callbacks", "pacing", "outputs"}: seconds (RunResult::WallSplit).
nlohmann::json wall_split_json(const RunResult::WallSplit& split);

void write_run_summary(const std::filesystem::path& file, const Scene& scene, const PhyxelSet& set,
                       Solver& solver, const RunOptions& options, const RunResult& result,
                       const HapticSession* haptics = nullptr,
                       const char* interrupted_by = nullptr);  // "SIGINT" when a signal stopped it

}  // namespace phyxel::app
