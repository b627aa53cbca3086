#!/usr/bin/env bash
# Installs every Debian package strata needs to build, test and run, then fetches the demo and test
# data (scripts/fetch-data.sh). Idempotent: when everything is present it only checks (dpkg-query,
# sha256sum) and returns in well under a second.
set -euo pipefail

packages=(
  # toolchain
  cmake ninja-build g++ pkg-config make
  # Vulkan: headers, loader, lavapipe (CPU device), validation layers, shader compiler and tools
  libvulkan-dev vulkan-tools mesa-vulkan-drivers vulkan-validationlayers glslang-tools spirv-tools
  libspirv-cross-c-shared-dev
  # libraries
  libglm-dev libglfw3-dev libimgui-dev doctest-dev libcli11-dev libstb-dev
  # label text (engine/core/font.cpp): faces read and rasterised by FreeType, shaped by HarfBuzz,
  # right-to-left text ordered by FriBiDi; DejaVu Sans, FreeSans and FreeSerif for characters it
  # lacks, WenQuanYi Micro Hei for Chinese, Japanese and Korean
  libfreetype-dev libharfbuzz-dev libfribidi-dev fonts-dejavu-core fonts-freefont-ttf
  fonts-wqy-microhei
  # vector stills: PDF through cairo; the tests rasterise SVG (rsvg-convert) and PDF (poppler)
  libcairo2-dev librsvg2-bin poppler-utils
  # file formats: gzip, DICOM, meshes, JSON, XML, JPEG (label pictures)
  zlib1g-dev libgdcm-dev libassimp-dev nlohmann-json3-dev libpugixml-dev libjpeg62-turbo-dev
  # videos: H.264 in MP4 and GIF (palettes by libavfilter) through FFmpeg's libraries; ffprobe
  # checks them in the tests
  libavcodec-dev libavformat-dev libavfilter-dev libswscale-dev libavutil-dev ffmpeg
  # the label writer's test validates its markups JSON against 3D Slicer's schema
  python3-jsonschema
  # the DICOM SEG reader's test opens a Segmentation that pydicom writes (with numpy's arrays)
  python3-pydicom python3-numpy
  # window tests without a display
  xvfb xauth xdotool
  # fuzzing (scripts/fuzz.sh): clang and its runtime libraries, libFuzzer among them
  clang libclang-rt-14-dev
)

cd "$(dirname "$0")/.."

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${db:Status-Status}' "$p" 2>/dev/null || true)
  [[ $status == installed ]] || missing+=("$p")
done
if ((${#missing[@]} > 0)); then
  echo "setup: installing ${missing[*]}"
  sudo=""
  if [[ $(id -u) != 0 ]]; then sudo=sudo; fi
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -q
  $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# Real data: downloaded into assets/cache and checksum-verified, not installed.
scripts/fetch-data.sh
