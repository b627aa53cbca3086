#!/usr/bin/env bash
# The layering of docs/ARCHITECTURE.md ("Code map"), checked on every `#include "dir/..."` of the
# libraries and the program: an include of a folder that a folder may not use, and a cycle of
# includes between files, each printed as file:line and the include. Usage: layering_check.sh
# [root] (the repository by default; tests/data/layering holds one of each fault).
set -euo pipefail
cd "${1:-$(dirname "$0")/..}"

# What each folder may include besides itself; shaders/shared ("shared/...") is for everyone.
declare -A allowed=(
  [engine/core]=""
  [engine/scene]="engine/core"
  [engine/gpu]="engine/core"
  [engine/graph]="engine/gpu engine/core"
  [labeling]="engine/scene engine/core"
  [passes]="engine/graph engine/gpu engine/scene engine/core"
  [frame]="passes labeling engine/graph engine/gpu engine/scene engine/core"
  [app]="frame passes labeling engine/graph engine/gpu engine/scene engine/core"
)
folders=(engine/core engine/scene engine/gpu engine/graph labeling passes frame app)

folder_of() {
  for f in "${folders[@]}" shared; do
    if [[ $1 == "$f"/* ]]; then echo "$f"; return; fi
  done
}

present=()
for f in "${folders[@]}"; do [[ -d $f ]] && present+=("$f"); done
includes=$(grep -rnE --include='*.h' --include='*.cpp' '^[[:space:]]*#[[:space:]]*include[[:space:]]+"[^"]+/' \
           "${present[@]}" || true)

faults=0
edges=""
while IFS=: read -r file line text; do
  [[ -z $file ]] && continue
  target=$(sed -E 's/^[^"]*"([^"]+)".*/\1/' <<<"$text")
  to=$(folder_of "$target")
  [[ -z $to ]] && continue  # (not one of strata's folders)
  from=$(folder_of "$file")
  if [[ $to == shared ]]; then
    target=shaders/$target
  elif [[ $to != "$from" && " ${allowed[$from]} " != *" $to "* ]]; then
    echo "$file:$line: $from may not include $to: $text"
    faults=$((faults + 1))
  fi
  edges+="$file $target"$'\n'
done <<<"$includes"

# A cycle of includes: tsort names the files of each loop; print their includes of each other.
if ! loops=$(tsort <<<"$edges" 2>&1 >/dev/null); then
  members=$(sed -nE 's/^tsort: ([^:]+)$/\1/p' <<<"$loops")
  echo "a cycle of includes between: $(paste -sd ' ' <<<"$members")"
  while read -r member; do
    while IFS= read -r hit; do
      target=$(sed -E 's/^[^"]*"([^"]+)".*/\1/; s#^shared/#shaders/shared/#' <<<"$hit")
      if grep -qxF "$target" <<<"$members"; then echo "$hit"; fi
    done < <(grep "^$member:" <<<"$includes" || true)
  done <<<"$members"
  faults=$((faults + 1))
fi

if ((faults > 0)); then
  echo "layering: $faults fault(s) (docs/ARCHITECTURE.md, \"Code map\", says which way includes go)"
  exit 1
fi
echo "layering: ok ($(wc -l <<<"$includes") includes)"
