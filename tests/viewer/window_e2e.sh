#!/usr/bin/env bash
# `phyxel view` in a real window: a virtual X server (Xvfb), lavapipe rendering (validation
# on) and presenting, key presses sent through the X server with xdotool, and the viewer's
# state read back from its window title (step, "(paused)", mono/stereo, "halted: ..."). Checks
# that the simulation runs, space pauses it (the step stops), n advances exactly one step, s
# switches to stereo, a drag (and the tool controls' right drag and shift + wheel) is taken,
# p saves mono and stereo pictures of an operating field (environment, backdrop, instruments),
# q quits with status 0 and validation said nothing; the same with the GPU solver; that a
# runaway simulation is halted with a message; and that SIGINT / SIGTERM close it (130 / 143).
# Registered with ctest by tests/CMakeLists.txt when the viewer is built.
#
#   window_e2e.sh PHYXEL SOURCE_DIR OUT_DIR
set -uo pipefail
phyxel="$1" src="$2" out="$3"

# fail MESSAGE: says what failed, shows the current viewer's log and how it exited.
fail() {
  echo "window_e2e: $*" >&2
  if [ -n "${log:-}" ] && [ -f "$log" ]; then
    sed 's/^/  view: /' "$log" >&2
  fi
  if [ -n "${pid:-}" ] && ! kill -0 "$pid" 2>/dev/null; then
    wait "$pid" 2>/dev/null
    echo "  view: exit status $?" >&2
  fi
  exit 1
}

if [ "${PHYXEL_E2E_INNER:-}" != 1 ]; then
  for tool in Xvfb xdotool; do
    command -v "$tool" >/dev/null ||
      fail "$tool is missing: scripts/install-deps.sh installs it (packages xvfb, xdotool)"
  done
  icd="$(ls /usr/share/vulkan/icd.d/lvp_icd*.json 2>/dev/null | head -1)"
  [ -n "$icd" ] || fail "lavapipe's ICD is not installed (package mesa-vulkan-drivers)"
  mkdir -p "$out"
  # Xvfb takes a free display itself (-displayfd), so two servers started at once cannot
  # race for one number as xvfb-run -a's do; -noreset keeps it up while no client is
  # connected (between two viewers); local sockets only, no cookie to share.
  rm -f "$out/xvfb.display"
  Xvfb -displayfd 3 -screen 0 1280x720x24 -nolisten tcp -noreset 3>"$out/xvfb.display" \
    2>"$out/xvfb.log" &
  xvfb=$!
  trap 'kill "$xvfb" 2>/dev/null' EXIT
  for _ in $(seq 600); do
    [ -s "$out/xvfb.display" ] && break
    kill -0 "$xvfb" 2>/dev/null || fail "Xvfb did not start ($out/xvfb.log)"
    sleep 0.1
  done
  display="$(head -1 "$out/xvfb.display")"
  [ -n "$display" ] || fail "Xvfb named no display in 60 s ($out/xvfb.log)"
  export VK_DRIVER_FILES="$icd" VK_ICD_FILENAMES="$icd" PHYXEL_E2E_INNER=1 DISPLAY=":$display"
  unset XAUTHORITY
  bash "$0" "$@"
  exit $?
fi

# Every wait below is a hang detector, not a timing check: it allows `slack` times the seconds
# it names, so that a loaded 2-core CI machine (the viewer at a few frames per second under
# lavapipe) never fails it; a viewer that hangs fails it all the same, later.
slack="${PHYXEL_E2E_SLACK:-4}"

# start_viewer LOG ARGS...: runs phyxel view ARGS in the background, finds its window.
pid="" win="" log=""
start_viewer() {
  log="$out/$1"
  shift
  "$phyxel" view "$@" >"$log" 2>&1 &
  pid=$!
  win=""
  for _ in $(seq $((600 * slack))); do
    win="$(xdotool search --pid "$pid" --name '^phyxel view' 2>/dev/null | head -1)"
    [ -n "$win" ] && return 0
    alive
    sleep 0.1
  done
  fail "no viewer window appeared in $((60 * slack)) s"
}
trap '[ -n "$pid" ] && kill $pid 2>/dev/null' EXIT
alive() { kill -0 "$pid" 2>/dev/null || fail "the viewer exited early ($log)"; }
title() { xdotool getwindowname "$win" 2>/dev/null; }
# wait_for REGEX SECONDS: until the title matches.
wait_for() {
  local t=""
  for _ in $(seq $(($2 * slack * 10))); do
    t="$(title)"
    [[ "$t" =~ $1 ]] && return 0
    alive
    sleep 0.1
  done
  fail "the title never matched '$1' in $(($2 * slack)) s (last: '$t')"
}
step_now() { title | sed -nE 's/.* step ([0-9]+).*/\1/p'; }
# quit_viewer: q closes the window; the viewer exits 0 and validation said nothing.
quit_viewer() {
  xdotool key --window "$win" q
  for _ in $(seq $((300 * slack))); do
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.1
  done
  kill -0 "$pid" 2>/dev/null && fail "q did not close the viewer in $((30 * slack)) s"
  wait "$pid"
  local status=$?
  pid=""
  [ "$status" = 0 ] || fail "the viewer exited with status $status ($log)"
  grep -q "vulkan validation" "$log" && fail "validation reported problems ($log)"
  return 0
}

# 1. The CPU reference solver: pause, one step, stereo, a drag, quit.
start_viewer view_cpu.log "$src/scenes/beam.json" --validate --threads 1
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
# The tool controls in a scene without haptic tools: a right drag and shift + wheel are taken.
xdotool mousemove --window "$win" 200 200 mousedown 3 mousemove --window "$win" 260 230 mouseup 3
xdotool keydown --window "$win" shift click --window "$win" 4 keyup --window "$win" shift
xdotool key --window "$win" space
wait_for " step [0-9]+  stereo " 30
quit_viewer
grep -q "simulating on cpu" "$log" || fail "the viewer did not say where it simulates ($log)"

# 2. The GPU solver (lavapipe here), rendered from its own buffers, in stereo.
start_viewer view_gpu.log "$src/scenes/beam.json" --device gpu --render stereo --validate
wait_for ' step [1-9][0-9]*  stereo ' 120
quit_viewer
grep -q "simulating on gpu:0 llvmpipe" "$log" || fail "the GPU solver was not used ($log)"

# 2b. An operating field (environment cube, backdrop, instruments, a mirror tumour): p saves
# the view as a PNG of the window's size; after a drag (a new view, so the backdrop's layer is
# drawn anew) and s, a stereo picture of the same size (each eye half the window). The pictures are looked at by people; here
# their size and that they are written.
png_size() { od -An -tu1 -j16 -N8 "$1" | awk '{ print $1*16777216 + $2*65536 + $3*256 + $4 "x" $5*16777216 + $6*65536 + $7*256 + $8 }'; }
rm -rf "${out:?}/pictures"
start_viewer view_field.log "$src/scenes/brain_tumour.json" --threads 1 --validate --out "$out/pictures"
wait_for ' step [1-9][0-9]*  mono ' 180
xdotool key --window "$win" space
wait_for ' \(paused\)  mono ' 60
xdotool key --window "$win" p
for _ in $(seq $((600 * slack))); do grep -q "saved" "$log" && break; alive; sleep 0.1; done
shot="$(sed -nE 's/^phyxel view: saved (.*\.png) .*/\1/p' "$log" | head -1)"
[ -f "$shot" ] || fail "p saved no picture ($log)"
[ "$(png_size "$shot")" = 640x360 ] || fail "the picture is $(png_size "$shot"), not 640x360"
xdotool mousemove --window "$win" 200 200 mousedown 1 mousemove --window "$win" 260 220 mouseup 1
xdotool key --window "$win" s
wait_for ' stereo ' 60
xdotool key --window "$win" p
for _ in $(seq $((600 * slack))); do [ "$(grep -c saved "$log")" -ge 2 ] && break; alive; sleep 0.1; done
shot2="$(sed -nE 's/^phyxel view: saved (.*\.png) .*/\1/p' "$log" | sed -n 2p)"
[ -f "$shot2" ] && [ "$shot2" != "$shot" ] || fail "the second p saved no new picture ($log)"
# Side by side in the same window: each eye gets half of it.
[ "$(png_size "$shot2")" = 640x360 ] || fail "the stereo picture is $(png_size "$shot2")"
quit_viewer

# 3. A runaway load: the viewer halts the simulation and says where, instead of drawing NaN.
cat >"$out/runaway.json" <<'JSON'
{
  "simulation": {"dt": 5e-5, "steps": 4000, "gravity": [0, 0, 0]},
  "objects": [{
    "name": "beam",
    "shape": {"type": "box", "min": [0, -0.01, -0.01], "max": [0.1, 0.01, 0.01]},
    "spacing": 0.0025,
    "material": {"young": 1e6, "poisson": 0.3, "density": 1000},
    "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [0.0005, 1, 1]}],
    "loads": [{"region": {"type": "box", "min": [0.09, -1, -1], "max": [1, 1, 1]},
               "force": [0, 0, -1e6]}]
  }]
}
JSON
start_viewer view_runaway.log "$out/runaway.json" --threads 1
wait_for ' halted: (runaway|non-finite) at step [0-9]+, phyxel [0-9]+' 120
halted_at="$(step_now)"
sleep 1.5
[ "$(step_now)" = "$halted_at" ] || fail "the simulation went on after it was halted"
quit_viewer
grep -q "the simulation is unstable" "$log" || fail "no message on standard error ($log)"

# 4. A haptic probe on the mouse: a right drag pushes it into a block through its haptic loop,
# the tissue pushes back, and the title shows the force the tool feels and its contacts.
cat >"$out/haptic.json" <<'JSON'
{
  "simulation": {"dt": 2e-4, "steps": 100000, "gravity": [0, 0, 0]},
  "objects": [{
    "name": "block",
    "shape": {"type": "box", "min": [0, 0, 0], "max": [0.04, 0.04, 0.02]},
    "spacing": 0.004,
    "material": {"young": 3000, "poisson": 0.45, "density": 1040, "damping": 20},
    "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.001]}]
  }],
  "tools": [{
    "name": "probe", "type": "probe", "control": "haptic",
    "shape": {"type": "sphere", "radius": 0.005},
    "path": [{"t": 0, "position": [0.02, 0.02, 0.027]}]
  }],
  "camera": {"position": [0.02, -0.1, 0.027], "target": [0.02, 0.02, 0.027], "up": [0, 0, 1]},
  "render": {"mode": "mono", "width": 320, "height": 240, "every": 5}
}
JSON
start_viewer view_haptic.log "$out/haptic.json" --threads 1
wait_for ' probe 0\.000 N \(0 contacts\)' 120
# 30 pixels down at the probe's depth (0.12 m, 45 degrees over 240 pixels) is 12 mm: the
# sphere's bottom goes from 2 mm above the block to 10 mm into it.
xdotool mousemove --window "$win" 160 120 sleep 0.3 mousedown 3 mousemove --window "$win" 160 135 \
  mousemove --window "$win" 160 150 sleep 0.3 mouseup 3
wait_for ' probe [0-9]+\.[0-9]+ N \([1-9][0-9]* contacts\)' 120
force="$(title | sed -nE 's/.* probe ([0-9.]+) N .*/\1/p')"
awk -v f="$force" 'BEGIN { exit !(f > 0) }' || fail "the probe in the block feels no force: $(title)"
quit_viewer
grep -q "haptic tools: right drag" "$log" || fail "the viewer did not list the tool controls ($log)"

# 4b. A scalpel put on the mouse (--hand): a right drag pulls its vertical blade through the
# block, and the title counts the pairs it cut. --hand with a name the scene lacks is refused.
cat >"$out/scalpel.json" <<'JSON'
{
  "simulation": {"dt": 2e-4, "steps": 100000, "gravity": [0, 0, 0]},
  "objects": [{
    "name": "block",
    "shape": {"type": "box", "min": [0, 0, 0], "max": [0.04, 0.04, 0.02]},
    "spacing": 0.004,
    "material": {"young": 3000, "poisson": 0.45, "density": 1040, "damping": 20},
    "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.001]}]
  }],
  "tools": [{
    "name": "scalpel", "type": "scalpel",
    "shape": {"type": "capsule", "radius": 0.0005, "length": 0.03},
    "blade": {"length": 0.03, "edge": [1, 0, 0]},
    "path": [{"t": 0, "position": [-0.003, 0.0201, 0.005], "axis": [0, 0, 1]}]
  }],
  "camera": {"position": [0.02, -0.1, 0.027], "target": [0.02, 0.02, 0.027], "up": [0, 0, 1]},
  "render": {"mode": "mono", "width": 320, "height": 240, "every": 5}
}
JSON
"$phyxel" view "$out/scalpel.json" --hand knife >"$out/view_hand.log" 2>&1 &&
  fail "--hand with an unknown tool was accepted"
grep -q "its tools: scalpel" "$out/view_hand.log" || fail "--hand knife: no clear message"
start_viewer view_scalpel.log "$out/scalpel.json" --threads 1 --hand scalpel
wait_for ' scalpel 0\.000 N \(0 contacts\)' 120
# The blade's tip is 3 mm left of the block; 150 pixels right at its depth (0.12 m, 45
# degrees over 240 pixels) is 6 cm: across the block, through the middle.
xdotool mousemove --window "$win" 100 167 sleep 0.3 mousedown 3 mousemove --window "$win" 150 167 \
  sleep 0.5 mousemove --window "$win" 200 167 sleep 0.5 mousemove --window "$win" 250 167 sleep 0.5 \
  mouseup 3
wait_for ' [1-9][0-9]* pairs cut' 120
cut="$(title | sed -nE 's/.* ([0-9]+) pairs cut.*/\1/p')"
quit_viewer

# 5. SIGINT and SIGTERM close the viewer as closing its window does, with status 130 and 143.
# The viewer has no output folder: it writes no file (run in an empty folder, which stays empty).
for sig in INT TERM; do
  mkdir -p "$out/cwd_$sig" && rm -rf "${out:?}/cwd_$sig/"*
  (cd "$out/cwd_$sig" && exec "$phyxel" view "$src/scenes/beam.json" --threads 1) \
    >"$out/view_sig$sig.log" 2>&1 &
  pid=$! log="$out/view_sig$sig.log"
  win=""
  for _ in $(seq $((600 * slack))); do
    win="$(xdotool search --pid "$pid" --name '^phyxel view' 2>/dev/null | head -1)"
    [ -n "$win" ] && break
    alive
    sleep 0.1
  done
  [ -n "$win" ] || fail "no viewer window appeared in $((60 * slack)) s"
  wait_for ' step [1-9][0-9]*  mono ' 120
  kill -s "$sig" "$pid"
  for _ in $(seq $((300 * slack))); do
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.1
  done
  kill -0 "$pid" 2>/dev/null && fail "SIG$sig did not close the viewer in $((30 * slack)) s"
  wait "$pid"
  status=$?
  pid=""
  want=130
  [ "$sig" = TERM ] && want=143
  [ "$status" = "$want" ] || fail "SIG$sig: the viewer exited with status $status, not $want ($log)"
  grep -q "closed by SIG$sig" "$log" || fail "SIG$sig: the viewer did not say why it closed ($log)"
  [ -z "$(ls -A "$out/cwd_$sig")" ] || fail "SIG$sig: the viewer wrote files: $(ls "$out/cwd_$sig")"
done

trap - EXIT
echo "window_e2e: ok (CPU: paused at step $paused_at, one step, stereo, drag; GPU solver; runaway halted at step $halted_at; haptic probe pressed with $force N; scalpel on the mouse cut $cut pairs; SIGINT 130, SIGTERM 143)"
