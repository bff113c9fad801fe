#!/usr/bin/env bash
# On the device machine (docs/performance.md, "Haptics and contact"): `phyxel bench --haptics`
# on the GPU: the 1 kHz haptic loop while the GPU solver runs the probe scene in real time at
# refine 1, 2.78, 3 and 6 (about 5k, 100k, 125k and 1M phyxels), 10 s each, then the contact cost per step
# on boxes of 10k, 100k and 1M phyxels. About 3 to 4 minutes on an H100. Expects .devbin and
# .gl from scripts/device-pack.sh, carried. Results go to
# $OUT: haptics.txt (every table), haptics.csv (every row) and haptics_rN.json per refine,
# haptics_contact.json.
set -uo pipefail
source "$(dirname "$0")/device-setup.sh"
nproc
"$b"/app/phyxel info 2>&1 | head -12
seconds="${SECONDS_PER_RUN:-10}"
: >"$out/haptics.txt"
rm -f "$out/haptics.csv"
collect() {  # $1: the run's --out folder, $2: name of its JSON in $OUT
  if [ ! -f "$out/haptics.csv" ]; then head -1 "$1/haptics.csv" >"$out/haptics.csv"; fi
  tail -n +2 "$1/haptics.csv" >>"$out/haptics.csv"
  cp "$1/haptics.json" "$out/$2"
}
for k in ${REFINES:-1 2.78 3 6}; do
  "$b"/app/phyxel bench --haptics --device gpu --refine "$k" --seconds "$seconds" --no-contact \
    --out "/tmp/phyxel-haptics-r$k" 2>&1 | tee -a "$out/haptics.txt"
  collect "/tmp/phyxel-haptics-r$k" "haptics_r$k.json"
done
"$b"/app/phyxel bench --haptics --device gpu --no-loop --sizes "${SIZES:-10000,100000,1000000}" \
  --out /tmp/phyxel-haptics-contact 2>&1 | tee -a "$out/haptics.txt"
collect /tmp/phyxel-haptics-contact haptics_contact.json
