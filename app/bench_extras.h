// `phyxel bench --skips`, `--stability` and `--render` (bench_skips.cpp, bench_stability.cpp,
// bench_render.cpp).
#pragma once

#include "app/commands.h"

namespace phyxel::app {

int bench_skips(const Args& args);
int bench_stability(const Args& args);
int bench_render_command(const Args& args);  // bench_render.cpp

}  // namespace phyxel::app
