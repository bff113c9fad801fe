#!/usr/bin/env bash
# The README's quick start:
#   scripts/dev.sh demo   install what is missing, build (Release), run the demo scene headless
#                         and render it (an aspirator takes a glioma's top layer) to out/demo.mp4 and
#                         out/demo.png (its last frame)
#   scripts/dev.sh test   install what is missing, build (Release), run the whole test suite
#                         (ctest: the GoogleTest areas and python_pytest, pytest over
#                         python/tests, whose exit status fails ctest like any test's), then
#                         the sanitizer job and a minute of fuzzing per reader (below)
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
  # Frames are drawn by Vulkan: on the GPU where there is one, else by Mesa's lavapipe on the
  # CPU (README.md says how long on a 2-core machine).
  rm -f out/frame_*.png
  build/app/phyxel run scenes/demo.json --out out --video out/demo.mp4
  last="$(ls out/frame_*.png | tail -1)"
  cp "$last" out/demo.png
  echo "demo: the video is out/demo.mp4 and its last frame out/demo.png; out/ also holds"
  echo "      summary.json, tools.csv, every frame (frame_*.png) and points_*.vtp (ParaView)"
else
  ctest --test-dir build --output-on-failure -j"$jobs" --timeout 900

  # Sanitizer job: a Debug build (-O1, asserts on) with AddressSanitizer (leaks included) and
  # UndefinedBehaviorSanitizer in build-asan, the first error fatal (docs/decisions.md
  # "Sanitizers in CI"). These test areas: the scene and OBJ readers (with the fuzzing
  # regressions), sampling, the CPU solver, contact, surgery (tools), cutting, the skipping of
  # settled regions and haptics (the 1 kHz loop's threads, UDP devices). They link only the
  # engine, so the job compiles no Vulkan, render or command-line code. Left out for time:
  # stability and validation (long runs of the solver code that physics covers), run and bench
  # (the whole command line), and the Vulkan areas (gpu_solver, vulkan, render). Also left
  # out: the fifteen tests that run longer than 20 s each under ASan (san_slow; their code runs
  # in the areas' other tests).
  san_areas=(scene sampling physics contact skip surgery cutting haptics)
  san_targets=("${san_areas[@]/#/test_}")
  cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DPHYXEL_SANITIZE=ON -DPHYXEL_WITH_WINDOW=OFF
  cmake --build build-asan -j"$jobs" --target "${san_targets[@]}"
  label="^($(
    IFS='|'
    echo "${san_areas[*]}"
  ))\$"
  san_slow='^(Contact\.(NoPhyxelInsideAProbePressedFiveMillimetres|HertzIndentation|'
  san_slow+='SlidingProbeFeelsCoulombFriction|StickingProbeDragsTheSurface)|'
  san_slow+='FreeVibration\.UndampedMotionConservesTotalEnergy|'
  san_slow+='Sleeping\.ChangesResultsOnlyBelowItsRestBound|'
  san_slow+='ScniBand\.(TakesThePhyxels|ItsForcesAre|KeepsTheMargin|ARunCheckpointed).*|'
  san_slow+='ProbePloughing\.(TissueThatCannotTear|ThickProbeThroughTissueThatTears).*|'
  san_slow+='Cutting\.AHalfDepthSlitSoftensTheBeamAndClosesWhenUnloaded|'
  san_slow+='Tearing\.ABarPulledByARisingLoadTearsWhenItsStressReachesTheTearStress|'
  san_slow+='EdgeResistance\.TheBreastsTurnAtItsApexDoesNotThrowTheTissue)$'
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --test-dir build-asan --output-on-failure -j"$jobs" --timeout 900 -L "$label" \
    -E "$san_slow"

  # Fuzzing: the scene, OBJ and checkpoint readers and the haptic protocol's decoder, a minute
  # each under ASan + UBSan (build-fuzz, clang); a new finding fails the run (scripts/fuzz.sh).
  # A fixed seed: the same inputs each run, so a finding is the code's, not the draw's.
  PHYXEL_FUZZ_FAIL=1 PHYXEL_FUZZ_SEED=1 scripts/fuzz.sh 60
fi
