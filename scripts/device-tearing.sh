#!/usr/bin/env bash
# On the device machine (docs/performance-log.md, "Tearing and suction"): the GPU tearing and
# suction tests on the real GPU, `phyxel bench --tearing` on boxes of 10k, 100k and 1M phyxels,
# and scenes/brain_tumour_removal.json on the GPU, without frames and with stereo frames drawn 60
# times per simulated second, three times each (the real-time factor, what was aspirated), then
# once with its frames written (the first and last to look at). Expects .devbin and .gl
# from scripts/device-pack.sh. Results go to $OUT: tearing.txt, tearing.json, brain_*.json.
set -uo pipefail
source "$(dirname "$0")/device-setup.sh"
if [ -x "$b/tests/test_gpu_solver" ]; then
  PHYXEL_TEST_DEVICE=gpu "$b"/tests/test_gpu_solver --gtest_filter='*Tear*:*Suction*:*Aspirat*' \
    2>&1 | tail -4 | tee "$out/tearing.txt"
fi
"$b"/app/phyxel bench --tearing --device gpu --sizes "${SIZES:-10000,100000,1000000}" \
  --out /tmp/phyxel-tearing 2>&1 | tee -a "$out/tearing.txt"
cp /tmp/phyxel-tearing/tearing.json "$out/tearing.json"
summary() {  # $1: the run's --out folder, $2: a label
  python3 -c "import json,sys; s = json.load(open('$1/summary.json')); a = s.get('aspiration', {}); print('$2: real-time factor', s['real_time_factor'], 'wall', s.get('wall_seconds'), 'split', s.get('wall_split_seconds'), 'aspiration events', a.get('events'), [(p['name'], round(p['removed_percent'], 2), round(p['removed_g'], 3)) for p in a.get('parts', [])], 'torn', s.get('cutting', {}).get('torn_pairs'))" 2>&1 |
    tee -a "$out/tearing.txt"
}
# The frames of a viewer: stereo, 60 per simulated second (render.every 104), drawn and read back
# but not written (--draw-only). A scene file beside the original keeps its relative paths.
python3 -c "import json; s = json.load(open('scenes/brain_tumour_removal.json')); s['render']['every'] = 104; json.dump(s, open('scenes/_brain_tumour_removal_60.json', 'w'))"
for r in ${REPEATS:-1 2 3}; do
  "$b"/app/phyxel run scenes/brain_tumour_removal.json --device gpu --render none --quiet \
    --out /tmp/phyxel-brain >/dev/null 2>&1
  summary /tmp/phyxel-brain "brain_tumour_removal --render none (run $r)"
  cp /tmp/phyxel-brain/summary.json "$out/brain_none_$r.json"
  "$b"/app/phyxel run scenes/_brain_tumour_removal_60.json --device gpu --draw-only --quiet \
    --out /tmp/phyxel-brain-frames >/dev/null 2>&1
  summary /tmp/phyxel-brain-frames "brain_tumour_removal, stereo frames 60/s drawn (run $r)"
  cp /tmp/phyxel-brain-frames/summary.json "$out/brain_frames_$r.json"
done
# Two written frames to look at (the first and the last).
"$b"/app/phyxel run scenes/brain_tumour_removal.json --device gpu --quiet \
  --out /tmp/phyxel-brain-png >/dev/null 2>&1
mkdir -p "$out/brain_frames"
ls /tmp/phyxel-brain-png/frame_*.png 2>/dev/null | sed -n '1p;$p' | xargs -r cp -t "$out/brain_frames"
