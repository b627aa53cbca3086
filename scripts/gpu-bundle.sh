#!/usr/bin/env bash
# Packs the Release build for a bare NVIDIA host (no Vulkan loader there): strata, the test
# binary, their libraries, the loader, and the Khronos validation layer so the GPU test suite
# runs there with validation on. Needs the workplace's ../shared/scripts/gpu-bundle.
#   scripts/gpu-bundle.sh [OUT=.gpu]
# On the host: cd .gpu && VK_LAYER_PATH=$PWD/layers ./run.sh strata bench sat --size 1024
#              cd .gpu && VK_LAYER_PATH=$PWD/layers ./run.sh strata_tests --test-suite=gpu
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-.gpu}
build=${BUILD:-build}
../shared/scripts/gpu-bundle "$out" "$build/app/strata"
cp -f "$build/tests/strata_tests" "$out/"
mkdir -p "$out/layers"
cp -f /usr/lib/x86_64-linux-gnu/libVkLayer_khronos_validation.so "$out/lib/"
cp -f /usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json "$out/layers/"
du -sh "$out"
