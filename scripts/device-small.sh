#!/usr/bin/env bash
# On the device machine (docs/performance-log.md, "Small scenes"): the lanes tests and the GPU
# parity tests on the real GPU, `phyxel bench` at 5k-1M phyxels for each lane count, and the
# brain block (scenes/brain_tumour.json) and the brain tumour removal without frames, three
# times each: physics substeps per wall second and the real-time factor. Expects .devbin and .gl
# from scripts/device-pack.sh. Results go to $OUT: small.txt, small.json, brain_*.json.
set -uo pipefail
source "$(dirname "$0")/device-setup.sh"
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm,clocks.mem --format=csv |
  tee "$out/small.txt"
if [ -x "$b/tests/test_gpu_solver" ]; then
  PHYXEL_TEST_DEVICE=gpu "$b"/tests/test_gpu_solver \
    --gtest_filter="${TESTS:-*Lane*:*BitIdentical*:*MatchTheCpu*:*Tear*:*Suction*}" 2>&1 |
    tail -4 | tee -a "$out/small.txt"
fi
"$b"/app/phyxel bench --device gpu --sizes "${SIZES:-5000,10000,20000,100000,1000000}" \
  --lanes "${LANES:-1,2,4,8,16,auto}" --repeats "${BENCH_REPEATS:-3}" --json "$out/small.json" \
  2>&1 | tee -a "$out/small.txt"
rate() {  # $1: summary.json, $2: a label
  python3 -c "import json; s = json.load(open('$1')); print('$2:', s['phyxels'], 'phyxels,', round(s['substeps_done'] / s['wall_seconds']), 'substeps/s, real-time factor', round(s['real_time_factor'], 3), 'split', s.get('wall_split_seconds'))" 2>&1 |
    tee -a "$out/small.txt"
}
for r in ${REPEATS:-1 2 3}; do
  for scene in ${SCENES:-brain_tumour brain_tumour_removal}; do
    "$b"/app/phyxel run "scenes/$scene.json" --device gpu --render none --quiet \
      --out "/tmp/phyxel-$scene" >/dev/null 2>&1
    rate "/tmp/phyxel-$scene/summary.json" "$scene --render none (run $r)"
    cp "/tmp/phyxel-$scene/summary.json" "$out/${scene}_$r.json"
  done
done
