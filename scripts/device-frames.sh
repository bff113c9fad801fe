#!/usr/bin/env bash
# On the device machine (docs/performance-log.md, "Frames while the solver runs"): the GPU tests of
# an advance left in flight, of the transfer queue and of the frame queue, then what a stereo
# 1080p frame every 1/60 s costs the solver at about 1M phyxels (`phyxel bench --render`: a
# shell of 1 030 966 phyxels, 280 000 surfels, $FRAMES frames, default 360), for this build
# and, interleaved, for every other build named in $BUILDS (folders holding a phyxel, default
# .devbin/base), three times. Results go to $OUT/frames.txt.
set -uo pipefail
source "$(dirname "$0")/device-setup.sh"
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm,clocks.mem --format=csv |
  tee "$out/frames.txt"
"$b"/app/phyxel info 2>&1 | grep -E "transfer|^device" | tee -a "$out/frames.txt"
# The tests of an advance in flight, of the transfer queue and of the frame queue, on the GPU.
for t in "test_gpu_solver *InFlight*:*FinishThemselves*:*Parity*:*RunLoop*" \
  "test_vulkan *Transfer*:DispatchTest.*" "test_render FrameQueue*:RenderFrames.*"; do
  set -- $t
  [ -x "$b/tests/$1" ] || continue
  echo "== $1 $2" | tee -a "$out/frames.txt"
  PHYXEL_TEST_DEVICE=gpu "$b/tests/$1" --gtest_filter="$2" 2>&1 | grep -E "FAILED|PASSED|rror" |
    head -12 | tee -a "$out/frames.txt"
done
for r in ${REPEATS:-1 2 3}; do
  for dir in "$b/app" ${BUILDS:-.devbin/base}; do
    [ -x "$dir/phyxel" ] || continue
    echo "== $dir (run $r)" | tee -a "$out/frames.txt"
    "$dir/phyxel" bench --render --device gpu --surfels 280000 --width 1920 --height 1080 \
      --frames "${FRAMES:-360}" 2>&1 | tail -4 | tee -a "$out/frames.txt"
  done
done
