// `phyxel bench --skips`, `--stability`, `--render` and `--haptics` (bench_skips.cpp,
// bench_stability.cpp, bench_render.cpp, bench_haptics.cpp), and the box scene they share.
#pragma once

#include <cstdint>

#include "app/commands.h"
#include "engine/scene/scene.h"

namespace phyxel::app {

int bench_skips(const Args& args);
int bench_stability(const Args& args);
int bench_render_command(const Args& args);  // bench_render.cpp
int bench_haptics(const Args& args);         // bench_haptics.cpp
int bench_cutting(const Args& args);         // bench_cutting.cpp
int bench_tearing(const Args& args);         // bench_tearing.cpp
int bench_sampling(const Args& args);        // bench_sampling.cpp
int bench_surgery(const Args& args);         // bench_surgery.cpp

// A cube of about `phyxels` points: 0.1 m on a side, clamped at z = 0, soft tissue material
// (cmd_bench.cpp; dt left at 1 for the caller to replace by the stable step).
Scene bench_scene(int64_t phyxels);

}  // namespace phyxel::app
