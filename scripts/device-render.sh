#!/usr/bin/env bash
# On the device machine (docs/performance.md, "Rendering"): the render tests on the GPU with
# validation, then `phyxel bench --render`. Expects binaries built on the development machine
# without the window viewer (the device machine has no GLFW), carried:
#   cmake -S . -B build-device -DPHYXEL_WITH_WINDOW=OFF && cmake --build build-device \
#     --target phyxel test_render
# and the Vulkan loader and validation layer packages in .gl/ (see
# /work/.library/device/README.md). Results go to $OUT.
set -uo pipefail
b="${PHYXEL_BUILD:-build-device}"
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
out="${OUT:-/tmp/phyxel-out}"
mkdir -p "$out"
if ! "$b"/app/phyxel info >/dev/null 2>&1; then
  export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
fi
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
