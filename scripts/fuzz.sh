#!/usr/bin/env bash
# Fuzzes the scene, OBJ and checkpoint readers and the haptic protocol's decoder with libFuzzer
# for a bounded time each. CI runs it for 60 s a target (scripts/dev.sh test) with
# PHYXEL_FUZZ_FAIL=1: a finding then fails the run. PHYXEL_FUZZ_SEED fixes libFuzzer's seed
# (CI: 1, so a run explores the same inputs each time; unset or 0: a new seed every run). Every
# test run replays what fuzzing found before (tests/scene/fuzz_regressions_test.cpp).
#   scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]
#   default 300 s, fuzz_scene fuzz_obj fuzz_checkpoint fuzz_haptic
# Needs clang and libclang-rt-14-dev (libFuzzer). Builds build-fuzz (clang, ASan + UBSan,
# -fsanitize=fuzzer); a CMAKE_CXX_COMPILER_LAUNCHER from the environment (ccache) is used.
# Targets run side by side, as many at a time as the machine has cores (PHYXEL_FUZZ_JOBS to
# change it; each target one process, -fork=1), so two cores fuzz four targets a minute each in
# two minutes of wall. Crashes do not stop a run (-ignore_crashes=1); they land in
# build-fuzz/artifacts/TARGET/, the grown corpus in build-fuzz/corpus/TARGET/ (kept between
# runs). Move each finding to tests/data/fuzz/TARGET/ with its fix: the regression test replays
# every file there.
set -euo pipefail
cd "$(dirname "$0")/.."

if ! command -v clang++ >/dev/null ||
  ! ls /usr/lib/llvm-*/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a >/dev/null 2>&1; then
  echo "fuzz: needs clang and libFuzzer (apt-get install clang libclang-rt-14-dev)" >&2
  exit 1
fi

seconds="${1:-300}"
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(fuzz_scene fuzz_obj fuzz_checkpoint fuzz_haptic)

CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DPHYXEL_FUZZ=ON -DPHYXEL_BUILD_TESTS=OFF -DPHYXEL_WITH_WINDOW=OFF >/dev/null
cmake --build build-fuzz -j2 --target "${targets[@]}"

export OMP_NUM_THREADS=1
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1}"

# Fuzzes one target for $seconds (its seeds copied into its corpus first); its libFuzzer log in
# build-fuzz/TARGET.log, a summary line on stdout.
fuzz_target() {
  local target="$1" seeds options
  local corpus="build-fuzz/corpus/$target" artifacts="build-fuzz/artifacts/$target"
  mkdir -p "$corpus" "$artifacts"
  case "$target" in
    fuzz_scene)
      seeds=(scenes scenes/validation tests/data/scenes tests/data/fuzz/fuzz_scene)
      options=(-dict=fuzz/scene.dict)
      ;;
    fuzz_obj)
      seeds=(tests/data/meshes tests/data/fuzz/fuzz_obj)
      options=(-dict=fuzz/obj.dict)
      ;;
    fuzz_checkpoint)
      seeds=(tests/data/fuzz/fuzz_checkpoint)
      options=(-max_len=16384)
      ;;
    fuzz_haptic)
      seeds=(tests/data/fuzz/fuzz_haptic)
      options=(-max_len=128)
      ;;
    *) seeds=() options=() ;;
  esac
  for dir in "${seeds[@]}"; do
    [ -d "$dir" ] || continue
    find "$dir" -maxdepth 1 -type f \( -name '*.json' -o -name '*.obj' -o -name '*.phx' -o -name '*.bin' \
      -o -name 'crash-*' -o -name 'timeout-*' -o -name 'oom-*' \) \
      -exec cp -n {} "$corpus/" \;
  done
  echo "fuzz: $target for ${seconds}s, corpus $corpus ($(ls "$corpus" | wc -l) files)"
  "build-fuzz/fuzz/$target" "$corpus" -artifact_prefix="$artifacts/" \
    -max_total_time="$seconds" -fork=1 -ignore_crashes=1 -ignore_ooms=1 -ignore_timeouts=1 \
    -timeout=10 -rss_limit_mb=2048 -seed="${PHYXEL_FUZZ_SEED:-0}" -print_final_stats=1 \
    "${options[@]}" >"build-fuzz/$target.log" 2>&1 || true
  local last time_s
  last="$(grep -E '^#[0-9]+:' "build-fuzz/$target.log" | tail -1)"
  time_s="${last#*time: }"
  echo "fuzz: $target done: executions ${last%%:*} in ${time_s%% *}, corpus $(ls "$corpus" | wc -l) files" \
    "($(du -sh "$corpus" | cut -f1)), findings $(ls "$artifacts" | wc -l) in $artifacts"
  grep -E '==ERROR|SUMMARY:|Test unit written' "build-fuzz/$target.log" | head -20 || true
}

# nproc answers OMP_NUM_THREADS (1, exported above) when it is set: the cores without it.
jobs="${PHYXEL_FUZZ_JOBS:-$(env -u OMP_NUM_THREADS -u OMP_THREAD_LIMIT nproc)}"
before=0
for target in "${targets[@]}"; do
  mkdir -p "build-fuzz/artifacts/$target"
  before=$((before + $(ls "build-fuzz/artifacts/$target" | wc -l)))
done
running=0
for target in "${targets[@]}"; do
  if [ "$running" -ge "$jobs" ]; then
    wait -n || true
    running=$((running - 1))
  fi
  fuzz_target "$target" &
  running=$((running + 1))
done
wait
after=0
for target in "${targets[@]}"; do
  after=$((after + $(ls "build-fuzz/artifacts/$target" | wc -l)))
done
found=$((after - before))
if [ "${PHYXEL_FUZZ_FAIL:-0}" = 1 ] && [ "$found" -gt 0 ]; then
  echo "fuzz: $found new findings (build-fuzz/artifacts/): fix them and add them to tests/data/fuzz/" >&2
  exit 1
fi
