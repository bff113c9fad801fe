# Sourced by the scripts/device-*.sh benchmarks on the device machine: unpacks the Vulkan loader
# packages carried in .gl/, points the loader at the NVIDIA driver where it finds none itself,
# and sets $b (the binaries: PHYXEL_BUILD, or .devbin from scripts/device-pack.sh) and $out
# (the results, $OUT).
b="${PHYXEL_BUILD:-.devbin}"
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
# The shared libraries a bare machine lacks (libav*, their codecs), packed by
# scripts/device-pack.sh; extra.tar.xz, where present, adds libraries linked since lib.tar.xz
# was packed (it is 46 MB: repacking it costs minutes of xz).
if [ -f "$b/lib.tar.xz" ]; then
  mkdir -p /tmp/phyxel-lib
  for f in "$b"/lib.tar.xz "$b"/extra.tar.xz; do
    [ -f "$f" ] && tar -C /tmp/phyxel-lib -xJf "$f"
  done
  # Only what the machine lacks: its own copies (which its GPU driver's libraries may need in
  # their own versions) come first.
  have="$(ldconfig -p)"
  for f in /tmp/phyxel-lib/*; do
    if grep -q "^[[:space:]]$(basename "$f") (" <<<"$have"; then rm -f "$f"; fi
  done
  export LD_LIBRARY_PATH="/tmp/phyxel-lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
fi
# Binaries carried compressed (scripts/device-pack.sh; a baseline's phyxel.xz likewise).
for f in "$b"/tests/*.xz "$b"/*/phyxel.xz; do
  [ -f "$f" ] && xz -dkf "$f" && chmod +x "${f%.xz}"
done
# Many Vulkan instances in one test binary: room for the driver's static TLS (compute/README.md).
export GLIBC_TUNABLES=glibc.rtld.optional_static_tls=16777216
# That static TLS is carved out of every thread's stack: with the default 8 MiB stacks the
# encoder's threads (libx264, for --video and the video-texture bench row) overflow theirs.
ulimit -s 65536
out="${OUT:-/tmp/phyxel-out}"
mkdir -p "$out"
if ! "$b"/app/phyxel info >/dev/null 2>&1; then
  export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
fi
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm,clocks.mem --format=csv
