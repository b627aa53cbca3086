#!/usr/bin/env bash
# Installs what is missing, then configures and builds strata into ${BUILD:-build}: everything,
# or the targets given (scripts/build.sh strata: the program alone, as scripts/demo does).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
build=${BUILD:-build}
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE="${BUILD_TYPE:-Release}" >/dev/null
targets=()
for t in "$@"; do targets+=(--target "$t"); done
cmake --build "$build" -j "$(nproc)" "${targets[@]}"
