#!/usr/bin/env bash
# On the device machine (docs/cutting.md, "Resection"): scenes/breast_resection.json on the GPU
# with its scalpel's cut_force_threshold set to each of $THRESHOLDS (N; default as shipped) and
# refined K times for each K in $KS (default 1 2), `--render none`; one line each: the
# carcinoma's outcome, the scalpel's largest cutting force against the threshold, its cutting
# substeps, the pairs cut, the tenaculum's pull and the real-time factor. Then, where $FRAMES
# names a threshold, that run again with mono frames. Expects .devbin and .gl from
# scripts/device-pack.sh, carried. Results go to $OUT: threshold.txt, the summaries, the frames.
set -uo pipefail
source "$(dirname "$0")/device-setup.sh"
scene="${SCENE:-scenes/breast_resection.json}"
work=/tmp/phyxel-threshold
mkdir -p "$work" "$out/summaries"
variant() {  # the scene with the scalpel's threshold set to $1, written to $work/t$1.json
  python3 - "$scene" "$1" "$work/t$1.json" <<'PY'
import json, os, sys
s = json.load(open(sys.argv[1]))
s['tools'][0]['cut_force_threshold'] = float(sys.argv[2])
base = os.path.dirname(os.path.abspath(sys.argv[1]))
if 'texture' in s.get('render', {}):
    s['render']['texture'] = os.path.join(base, s['render']['texture'])
json.dump(s, open(sys.argv[3], 'w'), indent=1)
PY
}
thresholds="${THRESHOLDS:-$(python3 -c "import json; print(json.load(open('$scene'))['tools'][0]['cut_force_threshold'])")}"
for t in $thresholds; do
  variant "$t"
  for k in ${KS:-1 2}; do
    dir="$work/t${t}_k$k"
    "$b"/app/phyxel run "$work/t$t.json" --device gpu --render none --refine "$k" --quiet \
      --out "$dir" >"$dir.log" 2>&1 || echo "threshold $t K=$k: exit $?: $(tail -1 "$dir.log")" |
      tee -a "$out/threshold.txt"
    cp "$dir/summary.json" "$out/summaries/t${t}_k$k.json" 2>/dev/null
    [ -f "$dir/tools.csv" ] && gzip -c "$dir/tools.csv" >"$out/summaries/t${t}_k$k.tools.csv.gz"
  done
done
python3 - "$work" <<'PY' | tee -a "$out/threshold.txt"
import glob, json, os, sys
for f in sorted(glob.glob(sys.argv[1] + '/t*_k*/summary.json')):
    s = json.load(open(f))
    tools = {t['name']: t for t in s.get('tools', [])}
    scalpel, ten = tools.get('scalpel', {}), tools.get('tenaculum', {})
    line = [os.path.basename(os.path.dirname(f)), f"{s['phyxels']} phyxels",
            f"rt {s['real_time_factor']:.2f}"]
    for inc in s.get('cutting', {}).get('inclusions', []):
        line.append(f"{inc['name']} {inc['removed_percent']:.1f} % "
                    f"{'whole' if inc['whole'] else 'NOT whole'} healthy {inc['healthy_removed_g']:.2f} g")
    line.append(f"pieces {s.get('cutting', {}).get('freed_pieces')}")
    line.append(f"pairs cut {s.get('cutting', {}).get('severed_pairs')}")
    line.append(f"max cut {scalpel.get('max_cut_force', 0):.4f} N")
    line.append(f"cutting substeps {scalpel.get('cutting_substeps')}")
    line.append(f"tenaculum {ten.get('max_force', 0):.2f} N")
    line.append(f"non-finite {s.get('non_finite')}")
    print('; '.join(line))
PY
for t in ${FRAMES:-}; do
  variant "$t"
  "$b"/app/phyxel run "$work/t$t.json" --device gpu --render mono --quiet --out "$work/frames_$t" \
    >"$work/frames_$t.log" 2>&1 || echo "frames $t: exit $?" | tee -a "$out/threshold.txt"
  mkdir -p "$out/frames_$t"
  cp "$work/frames_$t"/*.png "$out/frames_$t"/ 2>/dev/null
done
