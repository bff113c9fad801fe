#!/usr/bin/env bash
# On the device machine (docs/performance.md, "Surgery at higher resolution"): what stereo
# 1080p frames at 60/s cost the surgery runs, with a baseline binary ($BASE/app/phyxel, e.g.
# main's) and this tree's ($PHYXEL_BUILD or .devbin) one after the other on one card: the
# frame tests on the GPU (the frame queue's two submissions), then `phyxel bench --surgery
# --device gpu --refine 1,2` with each. Results go to $OUT: tests.txt, base.txt, new.txt and
# each run's surgery.json under base/ and new/.
set -uo pipefail
source "$(dirname "$0")/device-setup.sh"
base="${BASE:?BASE names the folder of the baseline binary}"
[ -f "$base/app/phyxel.xz" ] && xz -dkf "$base/app/phyxel.xz" && chmod +x "$base/app/phyxel"
if [ -x "$b/tests/test_render" ]; then
  PHYXEL_TEST_DEVICE=gpu "$b"/tests/test_render --gtest_filter='FrameQueue*:AspirationRender.*:Frames*:CutRender*' \
    >"$out/tests.txt" 2>&1
  tail -4 "$out/tests.txt"
fi
for who in base new; do
  bin="$b/app/phyxel"
  [ "$who" = base ] && bin="$base/app/phyxel"
  "$bin" bench --surgery --device gpu --refine "${KS:-1,2}" --out "$out/$who" \
    >"$out/$who.txt" 2>&1
  echo "== $who"
  cat "$out/$who.txt"
done
