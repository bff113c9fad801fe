// The benchmarks of `phyxel bench`, one per option (bench_*.cpp), and the box scene they share.
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "app/options.h"
#include "engine/scene/scene.h"

namespace phyxel::bench {

using app::Args;
using app::OptionParser;
using app::UsageError;

// `phyxel bench ARGS`: the benchmark its option names (the solver's scaling by default).
int bench_command(const Args& args);  // bench_scale.cpp

int bench_scale(const Args& args);           // bench_scale.cpp
int bench_skips(const Args& args);           // bench_skips.cpp
int bench_stability(const Args& args);       // bench_stability.cpp
int bench_render_command(const Args& args);  // bench_render.cpp
int bench_haptics(const Args& args);         // bench_haptics.cpp
int bench_cutting(const Args& args);         // bench_cutting.cpp
int bench_tearing(const Args& args);         // bench_tearing.cpp
int bench_sampling(const Args& args);        // bench_sampling.cpp
int bench_surgery(const Args& args);         // bench_surgery.cpp
int bench_accuracy(const Args& args);        // bench_accuracy.cpp

// Writes `json` to `file`, its folder created; nothing when `file` is empty (runtime_error
// naming the file when it cannot be written).
void write_json_file(const std::filesystem::path& file, const nlohmann::json& json);

// A cube of about `phyxels` points: 0.1 m on a side, clamped at z = 0, soft tissue material
// (bench_scale.cpp; dt left at 1 for the caller to replace by the stable step).
Scene bench_scene(int64_t phyxels);

}  // namespace phyxel::bench
