// phyxel: command-line entry point. Dispatches to the subcommands in commands.h.
#include <csignal>
#include <cstdio>
#include <exception>
#include <string>

#include "app/commands.h"
#include "app/options.h"

namespace {

void print_usage() {
  std::puts(
      "usage: phyxel <command> [options]\n"
      "\n"
      "commands:\n"
      "  run SCENE   simulate a scene file, write summary.json and .vtp points (run --help)\n"
      "  bench       measure solver speed and accuracy (bench --help)\n"
      "  info        list Vulkan devices and their limits\n"
      "  view SCENE  simulate a scene live in a window, mono or stereo (view --help)\n"
      "  soak SCENE  a long run sampled for memory, speed and energy (soak --help)\n"
      "  help        this text");
}

}  // namespace

int main(int argc, char** argv) {
  // A write past the file size limit (ulimit -f) then fails with EFBIG, which the writers report
  // naming the file, instead of SIGXFSZ killing the process without a word.
  std::signal(SIGXFSZ, SIG_IGN);
  if (argc < 2) {
    print_usage();
    return 2;
  }
  const std::string command = argv[1];
  const phyxel::app::Args args(argv + 2, argv + argc);
  try {
    if (command == "run") return phyxel::app::run_command(args);
    if (command == "bench") return phyxel::app::bench_command(args);
    if (command == "info") return phyxel::app::info_command(args);
    if (command == "view") return phyxel::app::view_command(args);
    if (command == "soak") return phyxel::app::soak_command(args);
    if (command == "help" || command == "--help" || command == "-h") {
      print_usage();
      return 0;
    }
  } catch (const phyxel::app::UsageError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "phyxel %s: %s\n", command.c_str(), e.what());
    return 1;
  }
  std::fprintf(stderr, "phyxel: unknown command '%s' (try 'phyxel help')\n", command.c_str());
  return 2;
}
