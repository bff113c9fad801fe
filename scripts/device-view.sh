#!/usr/bin/env bash
# On the device machine (docs/performance-log.md, "Interactive runs with frames"): what `phyxel
# view` does with a haptic probe, without the window (the H100 machine has no display): the
# probe scene with its probe on the haptic loop ("control": "haptic", the scripted device),
# its press and release repeated, paced to the wall clock, drawing a frame every 1/60 s of
# simulated time and reading it back (`--draw-only`: drawn, not written), at refine 1 and 2.78
# (about 5k and 100k phyxels), mono and stereo 1280 x 720, $SECONDS_PER_RUN (10) s each. Per
# run: the real-time factor, frames drawn per wall second, the haptic loop's period and the
# probe's contacts. Results go to $OUT/view.txt.
set -uo pipefail
source "$(dirname "$0")/device-setup.sh"
seconds="${SECONDS_PER_RUN:-10}"
: >"$out/view.txt"
for k in ${REFINES:-1 2.78}; do
  python3 - "$k" "$seconds" >/tmp/view_scene.json <<'PY'
import json, sys
k, seconds = float(sys.argv[1]), float(sys.argv[2])
s = json.load(open("scenes/probe_indent.json"))
for o in s["objects"]:
    o["spacing"] /= k
    if "support_radius" in o:
        o["support_radius"] /= k
dt = s["simulation"]["dt"]
s["simulation"]["steps"] = int(seconds / dt)
tool = s["tools"][0]
tool["control"] = "haptic"
# The press and release repeated for the whole run, so that the probe is in the tissue
# (moving or held) most of the time.
once, period = tool["path"], tool["path"][-1]["t"] + 0.05
tool["path"] = [dict(key, t=key["t"] + c * period) for c in range(int(seconds / period) + 2)
                for key in once]
s["render"].update({"width": 1280, "height": 720, "every": round(1 / 60 / dt)})
s["output"] = {"every": 0}
json.dump(s, sys.stdout)
PY
  for mode in mono stereo; do
    rm -rf /tmp/view-out
    "$b"/app/phyxel run /tmp/view_scene.json --device gpu --render "$mode" --draw-only \
      --haptic-device scripted --out /tmp/view-out --quiet >/tmp/view-log.txt 2>&1 ||
      tail -3 /tmp/view-log.txt | tee -a "$out/view.txt"
    python3 - "$k" "$mode" <<'PY' 2>&1 | tee -a "$out/view.txt"
import json, sys
s = json.load(open("/tmp/view-out/summary.json"))
h = s["haptics"][0]
steps, wall = s["steps_done"], s["wall_seconds"]
frames = steps // round(1 / 60 / s["dt_requested"]) + 1
print(f"refine {sys.argv[1]} {sys.argv[2]}: {s['phyxels']} phyxels, {steps} steps in {wall:.2f} s, "
      f"real-time factor {s['real_time_factor']:.3f}, {frames / wall:.1f} frames/s; haptic loop "
      f"p99 {h['period_p99_ms']:.2f} ms, max {h['period_max_ms']:.2f} ms, largest hand force "
      f"{h['max_hand_force']:.2f} N; probe: most phyxels in contact {s['tools'][0]['max_contacts']}, "
      f"largest force {s['tools'][0]['max_force']:.2f} N; split {s['wall_split_seconds']}")
PY
  done
done
