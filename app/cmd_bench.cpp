// phyxel bench: the benchmarks live in bench/ (bench/benches.h).
#include "app/commands.h"
#include "bench/benches.h"

namespace phyxel::app {

int bench_command(const Args& args) {
  return bench::bench_command(args);
}

}  // namespace phyxel::app
