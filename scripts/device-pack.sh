#!/usr/bin/env bash
# On the development machine: packs what the device machine's runs carry (docs/performance.md,
# "How the device figures are made"). Builds `phyxel` and the GPU test binary in the Release
# build folder $BUILD (default build/, configured if missing), copies them into .devbin/
# (stripped), with the shared libraries they need that a bare device machine lacks (GLFW,
# FFmpeg's libav* and their codecs) packed in .devbin/lib.tar.xz (about 130 MB unpacked, too
# much for the 64 MiB carry), and downloads the Vulkan
# loader packages into .gl/ (as /work/.library/device/README.md says). Both folders are
# git-ignored; a run names them in `carry` and sets PHYXEL_BUILD=.devbin. The glibc, libstdc++
# and libgcc of the machine are used, not carried.
set -euo pipefail
cd "$(dirname "$0")/.."
bdir="${BUILD:-build}"
[ -f "$bdir/CMakeCache.txt" ] || cmake -S . -B "$bdir" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$bdir" -j"${JOBS:-2}" --target phyxel test_gpu_solver test_render test_vulkan
rm -rf .devbin
mkdir -p .devbin/app .devbin/tests /tmp/devlib
rm -f /tmp/devlib/*
strip -o .devbin/app/phyxel "$bdir"/app/phyxel
# The test binaries travel compressed (device-setup.sh unpacks them).
for t in test_gpu_solver test_render test_vulkan; do
  strip -o .devbin/tests/$t "$bdir"/tests/$t
  xz -9 .devbin/tests/$t
done
ldd "$bdir"/app/phyxel | awk '/=> \//{print $3}' | sort -u |
  grep -Ev '/(libc|libm|libpthread|libdl|librt|libstdc\+\+|libgcc_s|ld-linux[^/]*)\.so' |
  while read -r lib; do cp -L "$lib" /tmp/devlib/; done
tar -C /tmp/devlib -cf - . | xz -9 -T"${JOBS:-2}" >.devbin/lib.tar.xz
du -sh .devbin
if [ ! -d .gl ]; then
  mkdir -p .gl /tmp/amd64/partial
  o='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64'
  # shellcheck disable=SC2086
  apt-get $o update >/dev/null
  # shellcheck disable=SC2086
  (cd .gl && apt-get $o download libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2 \
    vulkan-validationlayers)
fi
