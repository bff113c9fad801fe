#!/usr/bin/env bash
# The README's quick start:
#   scripts/dev.sh demo   install what is missing, build (Release), run the demo scene headless
#   scripts/dev.sh test   install what is missing, build (Release), run the whole test suite
set -euo pipefail
cd "$(dirname "$0")/.."

what="${1:-}"
case "$what" in
  demo | test) ;;
  *)
    echo "usage: scripts/dev.sh demo|test" >&2
    exit 2
    ;;
esac

scripts/install-deps.sh
jobs="$(nproc)"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$jobs"

if [ "$what" = demo ]; then
  build/app/phyxel run scenes/beam.json --out out
  echo "demo: outputs in out/ (summary.json, points_*.vtp: open them in ParaView)"
else
  ctest --test-dir build --output-on-failure -j"$jobs" --timeout 900
fi
