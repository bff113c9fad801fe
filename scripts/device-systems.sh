#!/usr/bin/env bash
# On the device machine (issue #33): the two surgery systems on the GPU. Runs every scene named
# in $SCENES (default the brain tumour removal and the breast resection) with `--render none`,
# prints one line of outcome each (aspirated parts; the carcinoma removed, whole, healthy mass;
# each scalpel's largest cutting force against its threshold), then renders the scenes named in
# $FRAMES (default none) in stereo. Expects .devbin and .gl from scripts/device-pack.sh, carried.
# Results go to $OUT: systems.txt, the summaries and the frames.
set -uo pipefail
source "$(dirname "$0")/device-setup.sh"
# Libraries this build links beyond device-pack.sh's lib.tar.xz (the readers' NIfTI and assimp).
if [ -f "$b/extra.tar.xz" ]; then
  tar -C /tmp/phyxel-lib -xJf "$b/extra.tar.xz"
  export LD_LIBRARY_PATH="/tmp/phyxel-lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
fi
scenes="${SCENES:-scenes/brain_tumour_removal.json scenes/breast_resection.json}"
mkdir -p /tmp/phyxel-systems "$out/summaries"
for scene in $scenes; do
  name="$(basename "$scene" .json)"
  dir="/tmp/phyxel-systems/$name"
  start=$(date +%s)
  "$b"/app/phyxel run "$scene" --device gpu --render none --quiet --out "$dir" >"$dir.log" 2>&1 ||
    echo "$scene: exit $?: $(tail -2 "$dir.log")" | tee -a "$out/systems.txt"
  echo "$name wall $(($(date +%s) - start)) s" >>"$out/systems.txt"
  cp "$dir/summary.json" "$out/summaries/$name.json" 2>/dev/null
  [ -f "$dir/tools.csv" ] && gzip -c "$dir/tools.csv" >"$out/summaries/$name.tools.csv.gz"
done
python3 - /tmp/phyxel-systems <<'PY' | tee -a "$out/systems.txt"
import glob, json, os, sys
for f in sorted(glob.glob(sys.argv[1] + '/*/summary.json')):
    s = json.load(open(f))
    line = [os.path.basename(os.path.dirname(f)), f"{s['phyxels']} phyxels",
            f"rt {s['real_time_factor']:.2f}"]
    for p in s.get('aspiration', {}).get('parts', []):
        line.append(f"{p['name']} {p['removed_percent']:.1f} % ({p['removed_g']:.3f} g)")
    for inc in s.get('cutting', {}).get('inclusions', []):
        line.append(f"{inc['name']} {inc['removed_percent']:.1f} % "
                    f"{'whole' if inc['whole'] else 'NOT whole'} healthy {inc['healthy_removed_g']:.2f} g")
    for t in s.get('tools', []):
        if 'max_cut_force' in t:
            line.append(f"{t['name']} max cut {t['max_cut_force']:.4f} N "
                        f"cutting substeps {t.get('cutting_substeps')}")
    print('; '.join(line))
PY
for scene in ${FRAMES:-}; do
  name="$(basename "$scene" .json)"
  "$b"/app/phyxel run "$scene" --device gpu --render stereo --quiet --out "$out/frames_$name" \
    >"$out/frames_$name.log" 2>&1 || echo "$scene frames: exit $?" | tee -a "$out/systems.txt"
  rm -f "$out/frames_$name"/*.vtp "$out/frames_$name"/*.bin
done
