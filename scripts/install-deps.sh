#!/usr/bin/env bash
# Installs the Debian 12 packages Phyxel needs, and only those that are missing.
# Idempotent: when everything is present it runs no apt-get at all.
set -euo pipefail

packages=(
  cmake g++ make pkg-config            # toolchain
  libeigen3-dev                        # CPU reference solver
  nlohmann-json3-dev                   # scene files, summaries
  libtinyobjloader-dev                 # mesh shapes (OBJ)
  libassimp-dev                        # mesh shapes as planning tools export them (STL, PLY)
  libnifti2-dev                        # image shapes: NIfTI-1/-2 label volumes (docs/decisions.md)
  mricron-data                         # MRI template and atlases of scenes/brain_mri_tumour_removal.json
  libstb-dev                           # PNG/JPEG textures and frames
  zlib1g-dev                           # deflate of the PNG frames (docs/decisions.md)
  libavcodec-dev libavformat-dev       # H.264/MP4 video of the frames (libavcodec59 brings libx264)
  libswscale-dev libavutil-dev         # RGBA -> YUV 4:2:0 for the encoder (docs/decisions.md)
  libvulkan-dev                        # Vulkan headers and loader
  mesa-vulkan-drivers                  # lavapipe: Vulkan on the CPU (tests, CI)
  vulkan-validationlayers              # validation layers, on in every GPU test
  glslang-tools spirv-tools            # shaders compiled at build time
  libglfw3-dev                         # windowed viewer
  xvfb xdotool                         # viewer test: virtual X server, key presses (docs/decisions.md)
  libgtest-dev                         # tests
  clang libclang-rt-14-dev             # libFuzzer: readers fuzzed a minute each in CI
  calculix-ccx                         # FEM reference solutions for validation
  gnuplot-nox                          # run-time-vs-error plot of phyxel bench --accuracy
  python3-dev pybind11-dev             # the phyxel Python module (python/, docs/python.md)
  python3-numpy python3-pytest         # its arrays and its tests
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null; then sudo="sudo"; else
    echo "install-deps: need root (or sudo) to install: ${missing[*]}" >&2
    exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
