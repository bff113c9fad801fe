// The `phyxel` subcommands. Each takes the arguments after its name and returns the exit code.
#pragma once

#include <string>
#include <vector>

namespace phyxel::app {

using Args = std::vector<std::string>;

int run_command(const Args& args);    // phyxel run SCENE ...      (cmd_run.cpp)
int bench_command(const Args& args);  // phyxel bench ...          (cmd_bench.cpp)
int info_command(const Args& args);   // phyxel info               (cmd_info.cpp)
int view_command(const Args& args);   // phyxel view SCENE ...     (cmd_view.cpp)
int soak_command(const Args& args);   // phyxel soak SCENE ...     (cmd_soak.cpp)

}  // namespace phyxel::app
