// `phyxel bench --skips` and `phyxel bench --stability` (bench_skips.cpp, bench_stability.cpp).
#pragma once

#include "app/commands.h"

namespace phyxel::app {

int bench_skips(const Args& args);
int bench_stability(const Args& args);

}  // namespace phyxel::app
