#!/usr/bin/env bash
# On the device machine (docs/performance.md, "Rendering"): the render tests on the GPU with
# validation, then `phyxel bench --render`. Expects .devbin and .gl from
# scripts/device-pack.sh (with test_render copied into .devbin/tests for the render tests) and
# the validation layer package in .gl/. Results go to $OUT.
set -uo pipefail
source "$(dirname "$0")/device-setup.sh"
# The tests find their goldens under the source path they were built in (PHYXEL_SOURCE_DIR).
src="${PHYXEL_BUILT_IN:-/work/main}"
if [ ! -e "$src" ]; then mkdir -p "$(dirname "$src")" && ln -s "$PWD" "$src"; fi
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm,clocks.mem --format=csv
"$b"/app/phyxel info 2>&1 | head -12
PHYXEL_TEST_DEVICE=gpu PHYXEL_TEST_OUT=/tmp/phyxel-test-out "$b"/tests/test_render 2>&1 | tail -4
"$b"/app/phyxel bench --render --device gpu --surfels "${SURFELS:-10000,100000,1000000}" \
  --frames "${FRAMES:-20}" --json "$out/render.json" 2>&1 | tee "$out/render.txt"
# End to end: the brain scene simulated on the GPU, stereo frames from the solver's buffers.
"$b"/app/phyxel run scenes/brain_tumour.json --device gpu --render stereo --steps "${STEPS:-200}" \
  --out /tmp/phyxel-brain 2>&1 | tail -3
last="$(ls /tmp/phyxel-brain/frame_*.png | tail -1)"
cp "$last" "$out/brain_last_frame.png"
