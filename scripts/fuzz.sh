#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, AddressSanitizer + UndefinedBehaviorSanitizer) into
# build/fuzz and runs each for a chosen time (docs/fuzzing.md):
#   bash scripts/fuzz.sh [--seconds N] [target ...]
# N: seconds per target (default 60); targets: default all of them, one after another. Each run
# starts from a scratch copy of tests/fuzz/corpus/<target>/ (the repository's corpus is never
# written) and stops at the first crash, leak, undefined behaviour, timeout (10 s per input) or
# allocation over 256 MB; the input is kept in build/fuzz/artifacts/. Exits 1 if any target
# found something, 2 on a usage error. CI: bash scripts/fuzz.sh --seconds 10.
set -euo pipefail
cd "$(dirname "$0")/.."

all_targets=(fuzz_scenario_yaml fuzz_map_yaml fuzz_replay_csv fuzz_eval_csv fuzz_decoder_input fuzz_cli_params
  fuzz_beacon_map_msg fuzz_serial_frames fuzz_bus_recording)
seconds=60
targets=()
usage() { sed -n '2,9p' "$0" | sed 's/^# \{0,1\}//'; }
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) [ $# -ge 2 ] || { usage >&2; exit 2; }; seconds=$2; shift 2 ;;
    --seconds=*) seconds=${1#--seconds=}; shift ;;
    -h | --help) usage; exit 0 ;;
    -*) echo "fuzz.sh: unknown option '$1'" >&2; usage >&2; exit 2 ;;
    *) targets+=("$1"); shift ;;
  esac
done
if ! [[ "$seconds" =~ ^[1-9][0-9]*$ ]]; then
  echo "fuzz.sh: --seconds takes a positive whole number, not '$seconds'" >&2
  exit 2
fi
[ ${#targets[@]} -gt 0 ] || targets=("${all_targets[@]}")
for t in "${targets[@]}"; do
  if [[ ! " ${all_targets[*]} " =~ " $t " ]]; then
    echo "fuzz.sh: unknown target '$t' (known: ${all_targets[*]})" >&2
    exit 2
  fi
done

dir=build/fuzz
flags="-O1 -fno-omit-frame-pointer -D_GLIBCXX_ASSERTIONS"
flags+=" -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all"
cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_COMPILER=clang++ \
  -DCMAKE_CXX_FLAGS="$flags" -DBEACONLOC_BUILD_FUZZERS=ON \
  -DBEACONLOC_BUILD_TESTS=OFF -DBEACONLOC_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$dir" -j 2 --target "${targets[@]}"

artifacts="$dir/artifacts"
mkdir -p "$artifacts"
# Scratch corpora, and the files the targets write (TMPDIR): on tmpfs where there is one.
if [ -z "${TMPDIR:-}" ] && [ -d /dev/shm ] && [ -w /dev/shm ]; then base=/dev/shm; else base=${TMPDIR:-/tmp}; fi
scratch=$(mktemp -d "$base/beaconloc-fuzz.XXXXXX")
trap 'rm -rf "$scratch"' EXIT
mkdir -p "$scratch/tmp"
export ASAN_OPTIONS="${ASAN_OPTIONS:-abort_on_error=1:detect_leaks=1:allocator_may_return_null=0}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
failed=()
for t in "${targets[@]}"; do
  corpus="$scratch/$t"
  mkdir -p "$corpus"
  if [ -d "tests/fuzz/corpus/$t" ]; then cp -r "tests/fuzz/corpus/$t/." "$corpus/"; fi
  options=(-max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=256
    -print_final_stats=1 -artifact_prefix="$artifacts/$t-")
  if [ -f "tests/fuzz/$t.dict" ]; then options+=(-dict="tests/fuzz/$t.dict"); fi
  echo "fuzz.sh: $t for $seconds s"
  log="$artifacts/$t.log"
  if TMPDIR="$scratch/tmp" "$dir/tests/fuzz/$t" "${options[@]}" "$corpus" >"$log" 2>&1; then
    status=ok
  else
    status=FAILED
    failed+=("$t")
    grep -E "ERROR: |runtime error: |SUMMARY: |Test unit written to" "$log" | head -n 12 || true
  fi
  # The last status line libFuzzer printed (executions, coverage, corpus) and its final stats.
  stats=$(grep -E "^#[0-9]+" "$log" | tail -n 1 || true)
  echo "fuzz.sh: $t $status: ${stats:-no status line}; $(ls "$corpus" | wc -l) corpus inputs; log $log"
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz.sh: found problems in: ${failed[*]} (inputs in $artifacts/)" >&2
  exit 1
fi
echo "fuzz.sh: no problem found in ${targets[*]}"
