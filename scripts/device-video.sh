#!/usr/bin/env bash
# On the device machine (docs/performance-log.md, "Video output" and "The backdrop of the example
# scenes"): --video's encode rate at stereo 1080p (bench --render's last line, 240 frames of
# the synthetic clip, twice with the default preset and once with superfast), the example
# scenes' frames at rest and while the view turns every frame (bench --render --scene, stereo
# 1920 x 1080 per eye), and whether recording slows a run: scenes/brain_tumour.json on the GPU
# with stereo 1080p frames 60 times a second of simulated time, drawn only, then drawn and
# encoded with --video (three times each). Expects .devbin and .gl from scripts/device-pack.sh.
# Results go to $OUT: video.txt, the bench JSON files, the runs' summaries and the last frame.
set -uo pipefail
source "$(dirname "$0")/device-setup.sh"
log="$out/video.txt"
for r in 1 2; do
  "$b"/app/phyxel bench --render --device gpu --surfels 1000000 --width 1920 --height 1080 \
    --frames 240 --no-solver --json "$out/render_$r.json" 2>&1 | tee -a "$log"
done
"$b"/app/phyxel bench --render --device gpu --surfels 10000 --width 1920 --height 1080 \
  --frames 240 --no-solver --video-preset superfast --json "$out/render_superfast.json" 2>&1 |
  tail -1 | tee -a "$log"
for s in brain_tumour breast_tumour brain_tumour_removal breast_resection; do
  "$b"/app/phyxel bench --render --device gpu --scene "scenes/$s.json" --width 1920 \
    --height 1080 --frames 60 --json "$out/scene_$s.json" 2>&1 | tee -a "$log"
done
# The brain scene at stereo 1080p, a frame every 69 steps of 0.24 ms (60.4 frames/s).
python3 - <<'EOF'
import json
s = json.load(open("scenes/brain_tumour.json"))
s["render"].update({"width": 1920, "height": 1080, "every": 69, "mode": "stereo"})
s["simulation"].pop("until_rest", None)
json.dump(s, open("scenes/_video_bench.json", "w"), indent=1)
EOF
summary() {  # $1: the run's --out folder, $2: a label, $3: the process's wall seconds
  python3 -c "import json; s = json.load(open('$1/summary.json')); print('$2: real-time factor', s['real_time_factor'], 'wall', s.get('wall_seconds'), 'process wall', $3, 'split', s.get('wall_split_seconds'))" 2>&1 |
    tee -a "$log"
}
timed() {  # runs "$@", sets $took to its wall seconds
  local t0
  t0=$(date +%s.%N)
  "$@" >/dev/null 2>&1
  took=$(python3 -c "print(round($(date +%s.%N) - $t0, 3))")
}
for r in 1 2 3; do
  rm -rf /tmp/pv-draw /tmp/pv-video
  timed "$b"/app/phyxel run scenes/_video_bench.json --device gpu --steps 4140 --draw-only \
    --quiet --out /tmp/pv-draw
  summary /tmp/pv-draw "brain_tumour stereo 1080p at 60 frames/s, drawn only (run $r)" "$took"
  timed "$b"/app/phyxel run scenes/_video_bench.json --device gpu --steps 4140 --draw-only \
    --quiet --video /tmp/pv-video.mp4 --out /tmp/pv-video
  summary /tmp/pv-video "brain_tumour stereo 1080p at 60 frames/s, drawn and encoded (run $r)" \
    "$took"
  ls -l /tmp/pv-video.mp4 2>&1 | tee -a "$log"
done
cp /tmp/pv-video/summary.json "$out/video_run_summary.json" 2>/dev/null
# The last frame of the recorded run, for a look (ffmpeg is not on the device: one PNG run).
"$b"/app/phyxel run scenes/_video_bench.json --device gpu --steps 69 --quiet \
  --out /tmp/pv-png >/dev/null 2>&1
cp /tmp/pv-png/frame_000069.png "$out/brain_stereo_1080p.png" 2>/dev/null
rm -f scenes/_video_bench.json
