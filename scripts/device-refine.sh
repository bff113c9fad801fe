#!/usr/bin/env bash
# On the device machine (docs/cutting.md, "Resolution"): the two surgery scenes refined K times
# (`phyxel run --refine K --device gpu --render none`) for K in $KS (default 1 1.5 2 2.5 3),
# one table of outcomes and real-time factors, then per K whether the outcome is K = 1's
# within 15 % (docs/cutting.md, "Resolution"). Expects .devbin and .gl from
# scripts/device-pack.sh, carried (PHYXEL_BUILD names another binary folder). Results go to
# $OUT: refine.txt (the table) and refine.json (every summary).
set -uo pipefail
source "$(dirname "$0")/device-setup.sh"
mkdir -p /tmp/phyxel-refine
scenes="${SCENES:-scenes/breast_resection.json scenes/brain_tumour_removal.json}"
for scene in $scenes; do
  for k in ${KS:-1 1.5 2 2.5 3}; do
    dir="/tmp/phyxel-refine/$(basename "$scene" .json)_$k"
    "$b"/app/phyxel run "$scene" --device gpu --render none --refine "$k" --quiet \
      --out "$dir" >"$dir.log" 2>&1 || echo "$scene K=$k: exit $?: $(tail -1 "$dir.log")"
  done
done
python3 - "$out" <<'PY' | tee "$out/refine.txt"
import glob, json, os, sys
rows = []
print(f"{'scene':22} {'K':>4} {'phyxels':>8} {'substeps':>8} {'rt factor':>9} {'callbacks s':>11} "
      f"{'wall s':>7}  outcome")
for f in sorted(glob.glob('/tmp/phyxel-refine/*/summary.json')):
    s = json.load(open(f))
    rows.append(s)
    name = os.path.basename(s['scene']).removesuffix('.json')
    outcome = []
    for inc in s.get('cutting', {}).get('inclusions', []):
        outcome.append(f"{inc['name']} {inc['removed_percent']:.1f} % removed, "
                       f"{'whole' if inc['whole'] else 'not whole'}, healthy {inc['healthy_removed_g']:.2f} g")
    a = s.get('aspiration')
    if a:
        parts = ', '.join(f"{p['name']} {p['removed_percent']:.1f} % ({p['removed_g']:.2f} g)"
                          for p in a['parts'])
        outcome.append(f"aspirated {parts}")
    w = s['wall_split_seconds']
    print(f"{name:22} {s['refine']:>4g} {s['phyxels']:>8} {s['substeps_per_step']:>8} "
          f"{s['real_time_factor']:>9.3f} {w['callbacks']:>11.2f} {s['wall_seconds']:>7.2f}  "
          + '; '.join(outcome))
json.dump(rows, open(os.path.join(sys.argv[1], 'refine.json'), 'w'), indent=1)
# Convergence (issue #29): against K = 1, each inclusion removed as fully and as whole, the
# healthy tissue with it and each part's aspirated mass within 15 %.
def outcome(s):
    o = {}
    for inc in s.get('cutting', {}).get('inclusions', []):
        o[inc['name'] + ' removed %'] = inc['removed_percent']
        o[inc['name'] + ' whole'] = inc['whole']
        o[inc['name'] + ' healthy g'] = inc['healthy_removed_g']
    for p in s.get('aspiration', {}).get('parts', []):
        o[p['name'] + ' aspirated g'] = p['removed_g']
    return o
base = {os.path.basename(s['scene']): outcome(s) for s in rows if s['refine'] == 1}
for s in sorted(rows, key=lambda s: (s['scene'], s['refine'])):
    ref = base.get(os.path.basename(s['scene']))
    if ref is None or s['refine'] == 1:
        continue
    bad = []
    for key, want in ref.items():
        got = outcome(s).get(key)
        if isinstance(want, bool) or want == 0:
            ok = got == want
        else:
            ok = got is not None and abs(got - want) <= 0.15 * abs(want)
        if not ok:
            bad.append(f"{key} {got} against {want}")
    print(f"{os.path.basename(s['scene'])} K={s['refine']:g}: " +
          ('converged' if not bad else 'NOT converged: ' + '; '.join(bad)))
PY
