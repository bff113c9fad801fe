#!/usr/bin/env bash
# The README's quick start:
#   scripts/dev.sh demo   install what is missing, build (Release), run the demo scene headless
#   scripts/dev.sh test   install what is missing, build (Release), run the whole test suite,
#                         then the sanitizer job (below)
# A CMAKE_CXX_COMPILER_LAUNCHER in the environment (ccache) is used; nothing needs it.
set -euo pipefail
cd "$(dirname "$0")/.."

what="${1:-}"
case "$what" in
  demo | test) ;;
  *)
    echo "usage: scripts/dev.sh demo|test" >&2
    exit 2
    ;;
esac

scripts/install-deps.sh
jobs="$(nproc)"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$jobs"

if [ "$what" = demo ]; then
  build/app/phyxel run scenes/beam.json --out out
  echo "demo: outputs in out/ (summary.json, points_*.vtp: open them in ParaView)"
else
  ctest --test-dir build --output-on-failure -j"$jobs" --timeout 900

  # Sanitizer job: a Debug build with AddressSanitizer (leaks included) and
  # UndefinedBehaviorSanitizer in build-asan, the first error fatal (docs/decisions.md
  # "Sanitizers in CI"). Only these test areas: the scene and OBJ readers (with the fuzzing
  # regressions), sampling, the CPU solver, contact, surgery (tools, cutting) and the skipping
  # of settled regions: the CPU code with the most indexing and ownership. They link only the
  # engine, so the job compiles no Vulkan, render or command-line code, and it builds and runs
  # in minutes on two cores. Left out for time: run (links and runs the whole command line),
  # haptics (sockets, a real-time loop), stability and validation (long runs of the solver
  # code that physics covers, minutes under ASan), and the Vulkan areas (gpu_solver, vulkan,
  # render).
  san_areas=(scene sampling physics contact skip surgery)
  san_targets=("${san_areas[@]/#/test_}")
  cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DPHYXEL_SANITIZE=ON -DPHYXEL_WITH_WINDOW=OFF
  cmake --build build-asan -j"$jobs" --target "${san_targets[@]}"
  label="^($(IFS='|'; echo "${san_areas[*]}"))\$"
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --test-dir build-asan --output-on-failure -j"$jobs" --timeout 900 -L "$label"
fi
