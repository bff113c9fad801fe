#!/usr/bin/env bash
# `phyxel view` in a real window: a virtual X server (Xvfb), lavapipe rendering (validation
# on) and presenting, key presses sent through the X server with xdotool, and the viewer's
# state read back from its window title (step, "(paused)", mono/stereo). Checks that the
# simulation runs, space pauses it (the step stops), n advances exactly one step, s switches
# to stereo, a drag is taken, q quits with status 0, and validation reported nothing.
# Registered with ctest by tests/CMakeLists.txt when the viewer is built.
#
#   window_e2e.sh PHYXEL SOURCE_DIR OUT_DIR
set -uo pipefail
phyxel="$1" src="$2" out="$3"

fail() {
  echo "window_e2e: $*" >&2
  [ -f "$out/view.log" ] && sed 's/^/  view: /' "$out/view.log" >&2
  exit 1
}

if [ "${PHYXEL_E2E_INNER:-}" != 1 ]; then
  for tool in xvfb-run xauth xdotool; do
    command -v "$tool" >/dev/null ||
      fail "$tool is missing: scripts/install-deps.sh installs it (packages xvfb, xauth, xdotool)"
  done
  icd="$(ls /usr/share/vulkan/icd.d/lvp_icd*.json 2>/dev/null | head -1)"
  [ -n "$icd" ] || fail "lavapipe's ICD is not installed (package mesa-vulkan-drivers)"
  mkdir -p "$out"
  export VK_DRIVER_FILES="$icd" VK_ICD_FILENAMES="$icd" PHYXEL_E2E_INNER=1
  exec xvfb-run -a -s "-screen 0 1280x720x24" bash "$0" "$@"
fi

"$phyxel" view "$src/scenes/beam.json" --validate --threads 1 >"$out/view.log" 2>&1 &
pid=$!
trap 'kill $pid 2>/dev/null' EXIT

alive() { kill -0 "$pid" 2>/dev/null || fail "the viewer exited early"; }
win=""
for _ in $(seq 600); do
  win="$(xdotool search --name '^phyxel view' 2>/dev/null | head -1)"
  [ -n "$win" ] && break
  alive
  sleep 0.1
done
[ -n "$win" ] || fail "no viewer window appeared in 60 s"
title() { xdotool getwindowname "$win" 2>/dev/null; }
# wait_for REGEX SECONDS: until the title matches.
wait_for() {
  local t=""
  for _ in $(seq $(($2 * 10))); do
    t="$(title)"
    [[ "$t" =~ $1 ]] && return 0
    alive
    sleep 0.1
  done
  fail "the title never matched '$1' in $2 s (last: '$t')"
}
step_now() { title | sed -nE 's/.* step ([0-9]+).*/\1/p'; }

wait_for ' step [1-9][0-9]*  mono ' 120
xdotool key --window "$win" space
wait_for ' \(paused\)  mono ' 30
paused_at="$(step_now)"
sleep 1.5  # the title refreshes every 0.5 s; the step must not move
[ "$(step_now)" = "$paused_at" ] || fail "the step moved while paused: $paused_at -> $(step_now)"
xdotool key --window "$win" n
wait_for " step $((paused_at + 1)) \(paused\) " 30
sleep 1.5
[ "$(step_now)" = "$((paused_at + 1))" ] || fail "n advanced more than one step: $(step_now)"
xdotool key --window "$win" s
wait_for ' stereo ' 30
xdotool mousemove --window "$win" 200 200 mousedown 1 mousemove --window "$win" 320 240 mouseup 1
xdotool key --window "$win" space
wait_for " step [0-9]+  stereo " 30
xdotool key --window "$win" q
for _ in $(seq 300); do
  kill -0 "$pid" 2>/dev/null || break
  sleep 0.1
done
kill -0 "$pid" 2>/dev/null && fail "q did not close the viewer in 30 s"
wait "$pid"
status=$?
trap - EXIT
[ "$status" = 0 ] || fail "the viewer exited with status $status"
grep -q "vulkan validation" "$out/view.log" && fail "validation reported problems"
grep -q "rendering on llvmpipe" "$out/view.log" || fail "the viewer did not say where it renders"
echo "window_e2e: ok (paused at step $paused_at, stepped once, stereo, orbit drag, quit)"
