#!/usr/bin/env bash
# On the device machine (docs/performance.md, "Soak"): `phyxel soak SCENE` on the GPU for STEPS
# steps (default 10^6; SCENE default scenes/soak_long.json, a block 318 mm long): the scalpel,
# grasper and aspirator repeat their 0.4 s cycle 0.4 mm further along the block each time
# ("repeat_shift"), on fresh tissue to the end. The soak samples resident memory, the GPU memory
# its context holds and what the driver says is left (VK_EXT_memory_budget), the step rate, the
# kinetic energy and the edits of every tenth; nvidia-smi samples the GPU's used memory every 5 s
# beside it. A
# `timeout` of LIMIT seconds (default 290) stops it with SIGTERM: the soak then writes the
# tenths it has. Expects the phyxel binary and .gl (scripts/device-pack.sh), carried. Results
# go to $OUT: soak.json, soak.txt (the table), nvidia_smi.csv.
set -uo pipefail
source "$(dirname "$0")/device-setup.sh"
# Libraries newer than device-pack.sh's list (libnifti2, assimp), where a pack carries them.
if [ -f "$b/extra.tar.xz" ]; then
  tar -C /tmp/phyxel-lib -xJf "$b/extra.tar.xz"
  export LD_LIBRARY_PATH="/tmp/phyxel-lib:${LD_LIBRARY_PATH:-}"
fi
"$b"/app/phyxel info 2>&1 | head -6
nvidia-smi --query-gpu=timestamp,memory.used --format=csv -l 5 >"$out/nvidia_smi.csv" &
smi=$!
timeout -s TERM "${LIMIT:-290}" "$b"/app/phyxel soak "${SCENE:-scenes/soak_long.json}" --device gpu \
  --steps "${STEPS:-1000000}" --out /tmp/phyxel-soak 2>&1 | tee "$out/soak.txt"
echo "soak exit status ${PIPESTATUS[0]}" | tee -a "$out/soak.txt"
kill "$smi"
cp /tmp/phyxel-soak/soak.json "$out/" 2>/dev/null || true
