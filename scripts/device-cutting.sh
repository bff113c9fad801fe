#!/usr/bin/env bash
# On the device machine (docs/performance.md, "Cutting"): the GPU cutting tests on the real
# GPU, `phyxel bench --cutting` on boxes of 10k, 100k and 1M phyxels, and scenes/scalpel_cut.json
# run on the GPU (its real-time factor), and scenes/breast_resection.json with and without
# frames. Expects .devbin and .gl from scripts/device-pack.sh, carried. Results go to $OUT:
# cutting.txt and cutting.json.
set -uo pipefail
source "$(dirname "$0")/device-setup.sh"
if [ -x "$b/tests/test_gpu_solver" ]; then
  PHYXEL_TEST_DEVICE=gpu "$b"/tests/test_gpu_solver --gtest_filter='*Cut*:*Contact*' 2>&1 |
    tail -4 | tee "$out/cutting.txt"
fi
"$b"/app/phyxel bench --cutting --device gpu --sizes "${SIZES:-10000,100000,1000000}" \
  --out /tmp/phyxel-cutting 2>&1 | tee -a "$out/cutting.txt"
cp /tmp/phyxel-cutting/cutting.json "$out/cutting.json"
"$b"/app/phyxel run scenes/scalpel_cut.json --device gpu --out /tmp/phyxel-scalpel 2>&1 |
  tail -2 | tee -a "$out/cutting.txt"
python3 -c "import json; s = json.load(open('/tmp/phyxel-scalpel/summary.json')); print('scalpel_cut on the GPU: real-time factor', s['real_time_factor'], 'severed', s.get('cutting'))" 2>&1 |
  tee -a "$out/cutting.txt"
# The breast resection: the solver alone, then with a stereo frame drawn (not written) every
# 1/60 s of simulated time (docs/performance.md, "Cutting").
python3 -c "import json; s = json.load(open('scenes/breast_resection.json')); s['render']['every'] = 72; json.dump(s, open('/tmp/breast_60.json', 'w'))"
for r in 1 2 3; do
  "$b"/app/phyxel run scenes/breast_resection.json --device gpu --render none --quiet \
    --out /tmp/phyxel-breast >/dev/null 2>&1
  python3 -c "import json; s = json.load(open('/tmp/phyxel-breast/summary.json')); print('breast_resection --render none: real-time factor', s['real_time_factor'], s['cutting']['inclusions'])" |
    tee -a "$out/cutting.txt"
  "$b"/app/phyxel run /tmp/breast_60.json --device gpu --draw-only --quiet \
    --out /tmp/phyxel-breast-60 >/dev/null 2>&1
  python3 -c "import json; s = json.load(open('/tmp/phyxel-breast-60/summary.json')); print('breast_resection, stereo frames at 60/s drawn: real-time factor', s['real_time_factor'], s['wall_split_seconds'])" |
    tee -a "$out/cutting.txt"
done
