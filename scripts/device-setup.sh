# Sourced by the scripts/device-*.sh benchmarks on the device machine: unpacks the Vulkan loader
# packages carried in .gl/, points the loader at the NVIDIA driver where it finds none itself,
# and sets $b (the build folder, PHYXEL_BUILD or build-device) and $out (the results, $OUT).
b="${PHYXEL_BUILD:-build-device}"
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
# Many Vulkan instances in one test binary: room for the driver's static TLS (compute/README.md).
export GLIBC_TUNABLES=glibc.rtld.optional_static_tls=16777216
out="${OUT:-/tmp/phyxel-out}"
mkdir -p "$out"
if ! "$b"/app/phyxel info >/dev/null 2>&1; then
  export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
fi
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm,clocks.mem --format=csv
