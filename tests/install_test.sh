#!/usr/bin/env bash
# `cmake --install` into a fresh prefix, then the installed program run from another folder: it
# finds its demo scene and data beside itself (share/strata), not in the source tree.
#   tests/install_test.sh BUILD_DIR PREFIX
set -euo pipefail
build=$1 prefix=$2
rm -rf "$prefix"
cmake --install "$build" --prefix "$prefix" >/dev/null
cd /
"$prefix/bin/strata" render "$prefix/share/strata/assets/scenes/head.json" --size 48 \
  -o "$prefix/head.png"
test -s "$prefix/head.png"
# bench's default scene, found beside the program
"$prefix/bin/strata" bench render --size 16 --runs 1 | grep -q "\"scene\": \"$prefix/share/strata/assets/scenes/head.json\""
echo "install: ok"
