#!/usr/bin/env bash
# On the device machine (docs/performance-log.md, "Scale: the largest box one H100 holds"): the
# two-part pair buffers (compute/pair_buffer.h) on the real GPU. `compare` (the default): the
# pair-split, capacity and parity tests, then `phyxel bench` at 10k, 100k and 1M phyxels for this
# build and, where $BASE/phyxel exists (default .devbin/base), a baseline build, interleaved,
# twice: what reading the pairs through two bindings costs. `scale`: `phyxel bench --no-check`
# at ${SIZES} (default 10M, 50M, 75M and 100M phyxels): the step rate, the device memory and the
# refusal past what the card binds; then the demo brain at 45M phyxels (pairs in two parts) must
# have no ill-conditioned moment matrix. Expects .devbin and .gl from scripts/device-pack.sh.
# Results go to $OUT: scale.txt and the bench JSON files.
set -uo pipefail
source "$(dirname "$0")/device-setup.sh"
base="${BASE:-.devbin/base}"
mode="${1:-compare}"
log="$out/scale.txt"
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm,clocks.mem,memory.total \
  --format=csv | tee -a "$log"
if [ "$mode" = compare ]; then
  if [ -x "$b/tests/test_gpu_solver" ]; then
    PHYXEL_TEST_DEVICE=gpu "$b"/tests/test_gpu_solver \
      --gtest_filter="${TESTS:-*Part*:*Capacity*:*MatchTheCpu*:*BitIdentical*:*Cut*}" 2>&1 |
      tail -4 | tee -a "$log"
  fi
  for r in ${REPEATS:-1 2}; do
    for bin in "$base" "$b/app"; do
      [ -x "$bin/phyxel" ] || continue
      echo "== $bin/phyxel, round $r" | tee -a "$log"
      "$bin"/phyxel bench --device gpu --sizes "${SIZES:-10000,100000,1000000}" --repeats 5 \
        --json "$out/compare_$(basename "$(dirname "$bin/x")")_$r.json" 2>&1 | tee -a "$log"
    done
  done
else
  "$b"/app/phyxel bench --device gpu \
    --sizes "${SIZES:-10000000,50000000,75000000,100000000}" --no-check --repeats 3 \
    --json "$out/scale.json" 2>&1 | tee -a "$log"
  # The bench cannot tell wrong pairs from right ones; a brain whose pairs are in two parts
  # (scenes/probe_indent.json at spacing 0.141 mm: 45M phyxels, 1.16e9 pairs) must have no
  # ill-conditioned moment matrix, as it has with one part at 30M and 40M.
  python3 - <<'PY'
import json
s = json.load(open("scenes/probe_indent.json"))
s["objects"][0]["spacing"] = 0.0001408
s["simulation"]["steps"] = 1
json.dump(s, open("scenes/.split_check.json", "w"))
PY
  "$b"/app/phyxel run scenes/.split_check.json --device gpu --render none --quiet \
    --out /tmp/phyxel-split-check >/dev/null 2>&1
  rm -f scenes/.split_check.json
  python3 -c "import json, sys; s = json.load(open('/tmp/phyxel-split-check/summary.json')); n = s['ill_conditioned_moment_matrices']; print('split check:', s['phyxels'], 'phyxels,', n, 'ill-conditioned moment matrices'); sys.exit(1 if n else 0)" 2>&1 | tee -a "$log" || { echo "split check FAILED" | tee -a "$log"; exit 1; }
fi
