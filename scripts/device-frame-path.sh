#!/usr/bin/env bash
# On the device machine (docs/performance.md, "Surgery at higher resolution"): what stereo
# 1080p frames at 60/s cost the surgery runs, with a baseline binary ($BASE/app/phyxel, e.g.
# main's) and this tree's ($PHYXEL_BUILD or .devbin) one after the other on one card: the
# frame tests on the GPU (the frame queue's two submissions; $GPU_TESTS, a gtest filter, adds
# test_gpu_solver's), then `phyxel bench --surgery --device gpu --refine 1,2 $BENCH_ARGS` with
# each, per scene of $SCENES (default both surgery scenes): base, $MID/app/phyxel's where MID is
# set, then new. Results go to $OUT: tests.txt, gpu_tests.txt, WHO-SCENE.txt and each run's
# surgery.json under WHO-SCENE/ (WHO: base, mid, new).
set -uo pipefail
source "$(dirname "$0")/device-setup.sh"
base="${BASE:?BASE names the folder of the baseline binary}"
for d in "$base" ${MID:-}; do
  [ -f "$d/app/phyxel.xz" ] && xz -dkf "$d/app/phyxel.xz" && chmod +x "$d/app/phyxel"
done
if [ -x "$b/tests/test_render" ]; then
  PHYXEL_TEST_DEVICE=gpu "$b"/tests/test_render --gtest_filter='FrameQueue*:AspirationRender.*:Frames*:CutRender*' \
    >"$out/tests.txt" 2>&1
  tail -4 "$out/tests.txt"
fi
if [ -n "${GPU_TESTS:-}" ] && [ -x "$b/tests/test_gpu_solver" ]; then
  PHYXEL_TEST_DEVICE=gpu "$b"/tests/test_gpu_solver --gtest_filter="$GPU_TESTS" \
    >"$out/gpu_tests.txt" 2>&1
  tail -4 "$out/gpu_tests.txt"
fi
for scene in ${SCENES:-brain_tumour_removal breast_resection}; do
  for who in base ${MID:+mid} new; do
    bin="$b/app/phyxel"
    [ "$who" = base ] && bin="$base/app/phyxel"
    [ "$who" = mid ] && bin="$MID/app/phyxel"
    # shellcheck disable=SC2086
    "$bin" bench --surgery --device gpu --refine "${KS:-1,2}" --scenes "scenes/$scene.json" \
      ${BENCH_ARGS:-} --out "$out/$who-$scene" >"$out/$who-$scene.txt" 2>&1
    echo "== $who $scene"
    cat "$out/$who-$scene.txt"
  done
done
