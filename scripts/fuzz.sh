#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/, clang, STRATA_FUZZ=ON) in build-fuzz and runs each over its
# seeds; exits non-zero on any finding: a crash, a sanitizer report, an exception other than
# strata::Error, a leak, a timeout or an allocation past the limits below (docs/fuzzing.md).
#
#   scripts/fuzz.sh [SECONDS] [TARGET...]      each target for SECONDS (default 10)
#   scripts/fuzz.sh --runs N [TARGET...]       each target for N executions (the long run)
#   scripts/fuzz.sh --scene-tests ...          first the scene and loader tests in the same build
#                                              (every library there has both sanitizers)
#
# New inputs that reach new code are kept in build-fuzz/corpus/<target> for the next run; a
# finding's input is written to build-fuzz/findings/ and the command to replay it is printed.
set -euo pipefail
cd "$(dirname "$0")/.."

scene_tests=0
if [[ ${1:-} == --scene-tests ]]; then
  scene_tests=1
  shift
fi
limit=(-max_total_time=10)
if [[ ${1:-} == --runs ]]; then
  limit=(-runs="$2")
  shift 2
elif [[ ${1:-} =~ ^[0-9]+$ ]]; then
  limit=(-max_total_time="$1")
  shift
fi
all=(fuzz_nifti fuzz_metaimage fuzz_nrrd fuzz_mgh fuzz_dicom_structure fuzz_dicom_seg
     fuzz_scene_json fuzz_thesis_xml fuzz_names_table fuzz_nifti_extensions
     fuzz_gra fuzz_transfer_function_json fuzz_markups_json fuzz_fcsv fuzz_label_csv
     fuzz_viewer_script
     fuzz_camera_path
     fuzz_text_layout
     fuzz_slicer_seg)
targets=("$@")
((${#targets[@]})) || targets=("${all[@]}")

build=${BUILD_FUZZ:-${BUILD:-build}-fuzz}
if [[ ! -f $build/CMakeCache.txt ]]; then
  CC=clang CXX=clang++ cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DSTRATA_FUZZ=ON -DSTRATA_VIDEO=OFF >/dev/null
fi
mkdir -p "$build/findings"
also=()
((scene_tests)) && also=(strata_scene_tests)
if ! cmake --build "$build" -j "$(nproc)" --target make_seeds "${targets[@]}" "${also[@]}" \
  >"$build/findings/build.log" 2>&1; then
  tail -40 "$build/findings/build.log"
  exit 1
fi
if ((scene_tests)); then
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "$build"/tests/strata_scene_tests --force-colors=0
fi

# Seeds: the binary ones generated (fuzz/make_seeds.cpp), the text ones the repository's files.
seeds=$build/seeds
rm -rf "$seeds"
"$build"/fuzz/make_seeds . "$seeds"
copy() {  # copy TARGET FILE... (missing files are skipped: assets/cache may not be fetched)
  local target=$1
  shift
  mkdir -p "$seeds/$target"
  for f in "$@"; do [[ -f $f ]] && cp "$f" "$seeds/$target/"; done
  return 0
}
copy fuzz_scene_json assets/scenes/*.json fuzz/corpus/fuzz_scene_json/*
copy fuzz_thesis_xml tests/data/voly-labeller/scenes/*.xml
copy fuzz_gra tests/data/voly-labeller/transferfunctions/*.gra
copy fuzz_transfer_function_json assets/transfer_functions/*.json
copy fuzz_markups_json tests/data/labels/*.mrk.json
copy fuzz_fcsv tests/data/labels/*.fcsv
copy fuzz_label_csv tests/data/labels/*.csv
copy fuzz_viewer_script fuzz/corpus/fuzz_viewer_script/*
copy fuzz_camera_path fuzz/corpus/fuzz_camera_path/*
copy fuzz_text_layout fuzz/corpus/fuzz_text_layout/*
copy fuzz_slicer_seg fuzz/corpus/fuzz_slicer_seg/*
copy fuzz_names_table fuzz/corpus/fuzz_names_table/* assets/cache/mricron/aal.nii.txt
copy fuzz_dicom_seg fuzz/corpus/fuzz_dicom_seg/*

dictionary() {
  case $1 in
    fuzz_transfer_function_json) echo fuzz/transfer_function_json.dict ;;
    fuzz_dicom_structure) echo fuzz/dicom.dict ;;
    *) echo "fuzz/${1#fuzz_}.dict" ;;
  esac
}

# Each process writes its inputs under $TMPDIR/strata-fuzz-<pid> (fuzz/fuzz_input.h): memory.
TMPDIR=$(mktemp -d /dev/shm/strata-fuzz.XXXXXX)
export TMPDIR
trap 'rm -rf "$TMPDIR"' EXIT
export ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1

# One target: its run, then its line (and the finding's excerpt) in $build/findings/<target>.line.
run_target() {
  local target=$1 corpus=$build/corpus/$1 log=$build/findings/$1.log status=ok
  mkdir -p "$corpus"
  # The inputs stay small (-max_len), so a lying header is the only way to a large allocation:
  # every legitimate one stays far below -malloc_limit_mb (a 64 KiB input inflates to 66 MB at
  # most, and its conversion to float needs four times that).
  local args=(-max_len=65536 -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=512
              -dict="$(dictionary "$target")" -artifact_prefix="$build/findings/$target-"
              -print_final_stats=1 "${limit[@]}")
  local start=$SECONDS
  rm -f "$build/findings/$target.line"
  "$build/fuzz/$target" "${args[@]}" "$corpus" "$seeds/$target" >"$log" 2>&1 || status=FINDING
  local runs speed
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  speed=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  {
    printf '%-30s %10s executions %5d s %7s exec/s  %s\n' "$target" "${runs:-?}" \
      $((SECONDS - start)) "${speed:-?}" "$status"
    if [[ $status != ok ]]; then
      grep -E 'ERROR|SUMMARY|fuzz:|Test unit written|==[0-9]+==' "$log" | head -20 | sed 's/^/    /'
      echo "    log: $log; replay: $build/fuzz/$target <the input written above>"
    fi
  } >"$build/findings/$target.line"
}

# As many targets at a time as there are cores (each is one process), reported in list order.
running=0
for target in "${targets[@]}"; do
  if ((running >= $(nproc))); then
    wait -n || true
    ((running--))
  fi
  run_target "$target" &
  ((++running))
done
wait || true
failed=()
for target in "${targets[@]}"; do
  cat "$build/findings/$target.line"
  grep -q ' FINDING$' "$build/findings/$target.line" && failed+=("$target")
done
if ((${#failed[@]})); then
  echo "fuzz: findings in ${failed[*]}" >&2
  exit 1
fi
