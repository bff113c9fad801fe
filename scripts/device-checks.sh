#!/usr/bin/env bash
# On the device machine (docs/performance.md, "The run loop's checks"): the GPU tests of the
# checks' reductions on the real GPU, then what the run loop's rest and sleep checks cost at
# about 1M phyxels. A 0.1 m box at 1 mm spacing (1 030 301 phyxels), clamped at its base and
# sagging under gravity, with until_rest and sleep on (bounds that are never met, so every
# check decides both), 3 000 steps, no output; the wall time split into advancing and checks
# (summary.json's wall_split_seconds), for this build and, where $BASE/phyxel exists (default
# .devbin/base), a baseline build, interleaved, three times. Results go to $OUT/checks.txt.
set -uo pipefail
source "$(dirname "$0")/device-setup.sh"
base="${BASE:-.devbin/base}"
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm,clocks.mem --format=csv |
  tee "$out/checks.txt"
if [ -x "$b/tests/test_gpu_solver" ]; then
  PHYXEL_TEST_DEVICE=gpu "$b"/tests/test_gpu_solver \
    --gtest_filter="${TESTS:-*ObjectMotion*:*Sleep*:*RunLoop*:*NoSkip*}" 2>&1 |
    tail -4 | tee -a "$out/checks.txt"
fi
cat >/tmp/checks_box.json <<'JSON'
{
  "simulation": {"dt": 5e-5, "steps": 3000, "gravity": [0, 0, -9.81],
                 "until_rest": {"kinetic_energy_below": 1e-30, "for_steps": 100000},
                 "sleep": {"kinetic_energy_below": 1e-30, "for_steps": 100000}},
  "objects": [{
    "name": "box",
    "shape": {"type": "box", "min": [0, 0, 0], "max": [0.1, 0.1, 0.1]},
    "spacing": 0.001,
    "material": {"young": 1e5, "poisson": 0.3, "density": 1000, "damping": 1.0},
    "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.0005]}]
  }],
  "output": {"every": 0}
}
JSON
split() {  # $1: summary.json, $2: a label
  python3 -c "import json; s = json.load(open('$1')); w = s['wall_split_seconds']; print('$2:', s['phyxels'], 'phyxels,', s['steps_done'], 'steps,', round(s['wall_seconds'], 3), 's, advance', round(w['advance'], 3), 's, checks', round(w['checks'], 4), 's,', round(s['steps_done'] / s['wall_seconds']), 'steps/s')" 2>&1 |
    tee -a "$out/checks.txt"
}
for r in ${REPEATS:-1 2 3}; do
  for which in new base; do
    bin="$b/app/phyxel"
    [ "$which" = base ] && bin="$base/phyxel"
    [ -x "$bin" ] || continue
    rm -rf /tmp/checks-out
    "$bin" run /tmp/checks_box.json --device gpu --render none --quiet --out /tmp/checks-out \
      >/tmp/checks-log.txt 2>&1 || tail -3 /tmp/checks-log.txt | tee -a "$out/checks.txt"
    split /tmp/checks-out/summary.json "$which (run $r)"
  done
done
